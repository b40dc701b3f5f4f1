#!/usr/bin/env bash
# One command on a fresh Debian machine: install what is missing, build (release), and run
# `spinesim demo`, which writes its report to demo-out/ (or $1).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release
out="${1:-demo-out}"
build/release/studies/spinesim demo --out "$out"
