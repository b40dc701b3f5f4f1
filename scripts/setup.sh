#!/usr/bin/env bash
# One command on a fresh Debian machine: install what is missing, build (release), and run
# `spinesim demo`, which writes its report to demo-out/ (or $1). Only the program and its
# libraries are built here (not the tests and benchmarks: scripts/test.sh builds those, reusing
# what this built), so a newcomer's first run waits for about half the compile work.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release --target spinesim
out="${1:-demo-out}"
build/release/app/spinesim demo --out "$out"
