#!/usr/bin/env bash
# One command: install what is missing, build (release) and run the test suite (everything
# except the tests labelled `slow`; run those with: ctest --test-dir build/release -L slow).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release
ctest --preset release -j2
