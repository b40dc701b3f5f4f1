#!/usr/bin/env bash
# One command: install what is missing, build (release) and run the test suite (everything
# except the tests labelled `slow`; run those with: ctest --test-dir build/release -L slow),
# then fuzz the file readers for a bounded time (fuzz/: clang's libFuzzer, one minute a target).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release
ctest --preset release -j2
cmake --preset fuzz
cmake --build --preset fuzz
ctest --preset fuzz
