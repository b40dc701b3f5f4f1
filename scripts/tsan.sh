#!/usr/bin/env bash
# ThreadSanitizer over the real-time threads: the servo loop, the disc worker (direct and
# multirate), the compliant stage's spine worker (forces and, on a 6-DOF device, moments), the
# latency probe and the recording writer — haptics_tests run them all — then whole runs of the
# program: a 6-DOF twist of the spine, and the viewer's session thread beside its GUI thread
# (`spinesim view` under Xvfb, when xvfb-run is present) on the disc and the dragged spine.
# Usage: scripts/tsan.sh   (builds build/tsan: about 40 min on 2 cores the first time)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset tsan > /dev/null
cmake --build --preset tsan -j"$(nproc)"
ctest --preset tsan -j1
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$PWD/scripts/tsan.supp"
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
bin=build/tsan/app/spinesim
cache=$(mktemp -d)
trap 'rm -rf "$cache"' EXIT
"$bin" haptics run --scene spine --triangles 1500 --spine multirate --model sigma.7 \
  --script data/haptics/twist_t1_axial.csv --duration 3 --no-realtime --cache-dir "$cache" \
  --json > /dev/null
echo "6-DOF twist (servo, spine worker, latency probe) under ThreadSanitizer: clean"
"$bin" haptics run --scene disc --disc-cell-size 3 --duration 2 --no-realtime \
  --cache-dir "$cache" --json > /dev/null
echo "multirate disc (servo, disc worker) under ThreadSanitizer: clean"
if command -v xvfb-run > /dev/null; then
  # The window closes at the screenshot (without one it stays open for a person to look).
  view() {
    xvfb-run -a -s '-screen 0 1280x960x24' "$bin" view --device sim --no-realtime \
      --cache-dir "$cache" --screenshot "$cache/view.png" --json "$@" > /dev/null
  }
  view --scene disc --disc-solver direct --disc-cell-size 4 --screenshot-at 2.5
  view --scene disc --disc-cell-size 3 --screenshot-at 2.5
  view --scene spine --triangles 1500 --spine multirate --screenshot-at 3 \
    --script data/haptics/drag_t1_lateral.csv
  echo "viewer sessions (GUI thread, session thread, disc and spine workers): clean"
fi
