#!/usr/bin/env bash
# Behaviour check for restructures: runs a fixed set of `spinesim` commands (one or more per
# verb, small meshes, deterministic inputs) and records what they print with --json, the files
# they write and the demo report; then compares two such records with the timing fields taken out.
#
#   scripts/compare-outputs.sh record BINARY DIR     # run the commands with BINARY, write DIR
#   scripts/compare-outputs.sh compare DIR_A DIR_B   # identical up to timings? (exit 1 if not)
#
# Typical use: record with the old binary (a checkout of the commit before the change), record
# with the new one, compare. Timing fields are keys that name seconds or a time of day
# (`seconds`, `*_s`, `*_seconds*`, `timings`, ...); the demo report's timing cells are masked
# the same way (scripts/normalize_output.py). Everything else must match exactly.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"

record() {
  local exe out
  exe="$(realpath "$1")"
  out="$(realpath -m "$2")"
  rm -rf "$out"
  mkdir -p "$out/files"
  cd "$out/files"
  local n=0
  run() {  # run NAME ARGS... : stdout -> NAME.json, exit status -> NAME.status
    local name="$1"
    shift
    n=$((n + 1))
    printf '[%2d] spinesim %s\n' "$n" "$*" >&2
    set +e
    OPENBLAS_NUM_THREADS=1 "$exe" "$@" >"../$name.json" 2>"../$name.stderr" </dev/null
    echo $? >"../$name.status"
    set -e
  }
  run mesh-disc mesh disc --level L4-L5 --cell-size 3 --out d.vtu --json
  run mesh-structured mesh disc --level T7-T8 --structured --out s.vtu --json
  run fem-case fem --mesh d.vtu --case flexion --json --out fem.vtu
  run fem-motion fem --mesh d.vtu --order 1 --motion 0,-0.1,0,0.5,0,0 --json
  run fem-wrench fem --mesh s.vtu --wrench 0,-500,0,0,0,0 --json
  run mss-static mss --mesh d.vtu --case compression --json --out mss.vtu
  run mss-dynamic mss --mesh s.vtu --case flexion --dt 1e-3 --steps 20 --frozen --frame-every 5 --json --out run.pvd
  run mss-compare mss compare --mesh s.vtu --order 1 --json --csv compare.csv
  run calibrate calibrate --mesh s.vtu --out tuned.json --json
  run mss-compare-tuned mss compare --mesh s.vtu --params tuned.json --load-scale 0.1 --json
  run calibrate-thesis calibrate --mesh s.vtu --train compression,flexion --holdout torsion --terms thesis --no-check --json --out tuned-thesis.json
  run study-probe study probe --mesh s.vtu --out probe-out --json
  run study-drive study drive --mesh s.vtu --out drive-out --materials real-disc,rubber --json
  run study-materials study materials --level T7-T8 --cell-size 4 --materials real-disc,rubber --csv materials.csv --json
  run spine-solve spine solve --force T7:0,0,300 --json --csv spine.csv
  run spine-solve-fusion spine solve --force T1:-200,0,0 --fusion L3-L4-L5 --json
  run study-validation study validation --json --csv validation.csv
  run study-fusion study fusion --json --csv fusion.csv
  run study-trends study trends --json --csv trends.csv
  run spine-database spine database --quiet --vertebrae T7 --superposition-on T7 --magnitudes 300 --out db.json --json
  run spine-database-check spine database --check --quiet --vertebrae T7 --superposition-on T7 --magnitudes 300 --out db.json --json
  run study-seating study seating --json --csv seating.csv
  run study-seating-sweep study seating-sweep --parameter backrest-recline --values 100,120 --json
  run mesh-vertebrae mesh vertebrae --level L3 --triangles 400 --out vertebrae-out --json
  run haptic-plane study haptic-plane --json
  run refused-mesh mss --mesh no-such-file.vtu --case compression --json
  run refused-flag spine solve --force T7:1,2 --json
  # Readable reports (stdout without --json) of the verbs whose drivers print them.
  run fem-text fem --mesh d.vtu --case flexion
  run mss-text mss --mesh d.vtu --case compression
  run mss-dynamic-text mss --mesh s.vtu --case flexion --dt 1e-3 --steps 20 --frozen
  run study-probe-text study probe --mesh s.vtu --out probe-text-out --quiet
  run study-drive-text study drive --mesh s.vtu --out drive-text-out --materials real-disc,rubber --quiet
  run study-materials-text study materials --level T7-T8 --cell-size 4 --materials real-disc,rubber --quiet
  run spine-database-text spine database --quiet --vertebrae T7 --superposition-on T7 --magnitudes 300 --out db-text.json
  run spine-database-check-text spine database --check --quiet --vertebrae T7 --superposition-on T7 --magnitudes 300 --out db.json
  run demo demo --out demo-out
  run demo-json demo --out demo-json-out --json --quiet
  echo "recorded $n commands in $out" >&2
}

compare() {
  python3 "$here/normalize_output.py" "$1" "$2"
}

case "${1:-}" in
  record) [ $# -eq 3 ] || { echo "usage: $0 record BINARY DIR" >&2; exit 2; }; record "$2" "$3" ;;
  compare) [ $# -eq 3 ] || { echo "usage: $0 compare DIR_A DIR_B" >&2; exit 2; }; compare "$2" "$3" ;;
  *) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
esac
