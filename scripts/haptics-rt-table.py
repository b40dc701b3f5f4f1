#!/usr/bin/python3
"""Runs every haptic scene and hostile trajectory once and prints the real-time table of
docs/benchmarks.md: the loop's own compute percentiles and missed deadlines beside the floor the
program measured in the same run (a bare periodic thread at the same priority).

    scripts/haptics-rt-table.py [build/release/app/spinesim] [--rows spine,disc,...] > table.md

Run it on a machine left alone: each row is one `spinesim haptics run ... --json` (about 2 to
12 s). The verdict column compares the misses with 1.5x the floor's late wake-ups.
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "data", "haptics")

# (scene, label, extra arguments)
ROWS = [
    ("spine", "stroke_spinous.csv", []),
    ("spine", "drag_t1_lateral.csv --spine multirate",
     ["--script", os.path.join(DATA, "drag_t1_lateral.csv"), "--spine", "multirate"]),
    ("spine", "twist_t1_axial.csv --spine multirate --model sigma.7",
     ["--script", os.path.join(DATA, "twist_t1_axial.csv"), "--spine", "multirate",
      "--model", "sigma.7"]),
    ("plane", "default", []),
    ("vertebra", "default", []),
    ("disc", "default (multirate, 21k tets)", []),
    ("disc", "--disc-model fem (the linear FEM disc, 21k tets)", ["--disc-model", "fem"]),
] + [("spine", "hostile:" + h, ["--script", "hostile:" + h])
     for h in ["teleport", "start-inside", "sweep", "skim", "shake", "hammer"]] + [
    ("spine", "hostile:hammer --spine multirate",
     ["--script", "hostile:hammer", "--spine", "multirate"]),
    ("plane", "hostile:sweep", ["--script", "hostile:sweep"]),
    ("plane", "hostile:shake", ["--script", "hostile:shake"]),
]


def run(spinesim, scene, extra):
    cmd = [spinesim, "haptics", "run", "--scene", scene, "--device", "sim", "--json"] + extra
    if scene == "disc":
        cmd += ["--level", "L4-L5"]
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(" ".join(cmd) + ": " + out.stderr.strip())
    return json.loads(out.stdout)


def main():
    args = sys.argv[1:]
    spinesim = os.path.join(HERE, "..", "build", "release", "app", "spinesim")
    only = None
    while args:
        a = args.pop(0)
        if a == "--rows":
            only = set(args.pop(0).split(","))
        else:
            spinesim = a
    print("| scene | script | ticks | compute p50 / p99 / p99.9 / max (µs) | missed | "
          "floor: late wake-ups | floor latency p99 / max (µs) | max force (N) | "
          "misses / floor |")
    print("|---|---|---:|---|---:|---:|---|---:|---:|")
    for scene, label, extra in ROWS:
        if only and scene not in only:
            continue
        j = run(spinesim, scene, extra)
        c, f = j["compute_us"], j["floor"]
        ticks, missed = j["ticks"], j["missed_deadlines"]
        late, wakeups = f["late"], f["wakeups"]
        floor_pct = 100.0 * late / max(wakeups, 1)
        ratio = (missed / ticks) / (late / wakeups) if late else float("inf") if missed else 0
        print(f"| {scene} | {label} | {ticks} | {c['p50']:.1f} / {c['p99']:.1f} / "
              f"{c['p999']:.1f} / {c['max']:.0f} | {missed} ({100.0 * missed / ticks:.2f} %) | "
              f"{late} ({floor_pct:.2f} %) | {f['latency_us']['p99']:.0f} / "
              f"{f['latency_us']['max']:.0f} | {j['max_force_n']:.2f} | "
              f"{'-' if ratio == float('inf') else f'{ratio:.2f}'} |", flush=True)


if __name__ == "__main__":
    main()
