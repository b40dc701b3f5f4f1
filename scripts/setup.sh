#!/usr/bin/env bash
# One command on a fresh Debian machine: install what is missing, build (release), and run
# `spinesim demo`, which writes its report to demo-out/ (or $1). Only the program, the Python
# module and their libraries are built here (not the tests and benchmarks: scripts/test.sh builds those, reusing
# what this built), so a newcomer's first run waits for about half the compile work.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release --target spinesim spinesim_python
# `import spinesim` from any folder: a .pth file in the user's site-packages (Debian's python3,
# and any other Python of the same version) names the build's package folder.
site="$(/usr/bin/python3 -m site --user-site)"
mkdir -p "$site"
echo "$PWD/build/release/python" > "$site/spinesim.pth"
echo "setup: python3 -c 'import spinesim' works (via $site/spinesim.pth)"
out="${1:-demo-out}"
build/release/app/spinesim demo --out "$out"
