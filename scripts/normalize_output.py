#!/usr/bin/env python3
"""Compares two records of scripts/compare-outputs.sh, timing fields taken out.

A record is a folder: NAME.json (stdout of one command), NAME.status (its exit status),
NAME.stderr, and files/ (everything the commands wrote). JSON is compared as data, with the
keys in TIMING_KEYS and the provenance dropped wherever they stand; text files are compared line by line after
TIMING_TEXT masks durations. Numbers that are not bit-identical but agree to ROUND_OFF relative to
the largest magnitude of their array (or line) are counted separately as round-off: floating-point
sums depend on the order of operations, which a change of compiler flags or of what the linker
keeps may alter. Prints one line per real difference and a summary; exit 1 when anything differs
beyond round-off.
"""
import json
import os
import re
import sys

ROUND_OFF = 1e-9
round_off = {"count": 0, "worst": 0.0}
spacing = {"lines": 0}  # readable text that differs only in white space (realigned table columns)


def close(a, b, scale):
    """Equal, or equal to round-off relative to `scale`; counts the round-off cases."""
    if a == b:
        return True
    if isinstance(a, bool) or isinstance(b, bool):
        return False
    d = abs(a - b) / max(scale, 1e-300)
    if d <= ROUND_OFF:
        round_off["count"] += 1
        round_off["worst"] = max(round_off["worst"], d)
        return True
    return False


def is_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)

# Measured durations and rates: they differ from run to run of the same binary.
TIMING_KEYS = re.compile(
    r"(^|_)(seconds|timings?)($|_)|_s$|_ms$|_us$|^elapsed|per_second|_rate_hz$|^generated_at$")
# Durations in readable text ("2.31 s", "0.42 ms", "(1.2 s)", "Total 3.1 s", "12 s/it").
TIMING_TEXT = re.compile(r"\d+(\.\d+)?(e[-+]?\d+)?\s?(s|ms|us|µs|min)\b")
# The size of a written file that itself holds timings (the spine database) varies with them.
VARYING_KEYS = {"bytes"}
# Inputs that look like timings but are not (kept).
NOT_TIMING = {"speed_mm_s", "dt_s", "time_s", "hold_s", "rest_s", "duration_s", "start_s", "t_s", "end_s", "frame_dt_s"}


# What made an output (binary path, commit, command line): differs between the two records.
PROVENANCE_KEYS = {"provenance"}
PROVENANCE_TEXT = [
    re.compile(r"^# provenance: .*$", re.M),                                  # CSV first line
    re.compile(r'<DataArray type="UInt8" Name="provenance"[^>]*>[^<]*</DataArray>\s*'),  # VTU
    re.compile(r"\n## Provenance\n.*\Z", re.S),                               # markdown report
    re.compile(r"<footer><h2>Provenance</h2>.*?</footer>", re.S),              # report.html
]


def strip(value):
    if isinstance(value, dict):
        return {k: strip(v) for k, v in value.items()
                if k not in VARYING_KEYS and k not in PROVENANCE_KEYS and (k in NOT_TIMING or not TIMING_KEYS.search(k))}
    if isinstance(value, list):
        return [strip(v) for v in value]
    return value


def diff(a, b, path, out, scale=None):
    if is_number(a) and is_number(b):
        if not close(a, b, scale if scale is not None else max(abs(a), abs(b))):
            out.append(f"{path}: {a!r} != {b!r}")
        return
    if type(a) != type(b):
        out.append(f"{path}: {json.dumps(a)[:80]} != {json.dumps(b)[:80]}")
    elif isinstance(a, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                out.append(f"{path}.{k}: only in {'second' if k not in a else 'first'}")
            else:
                diff(a[k], b[k], f"{path}.{k}", out)
    elif isinstance(a, list):
        if len(a) != len(b):
            out.append(f"{path}: length {len(a)} != {len(b)}")
        nums = [abs(v) for v in a + b if is_number(v)]
        s = max(nums) if nums else None
        for i, (x, y) in enumerate(zip(a, b)):
            diff(x, y, f"{path}[{i}]", out, s)
    elif a != b:
        out.append(f"{path}: {a!r} != {b!r}")


def load_json(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    if not text.strip():
        return None
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return {"not_json": text}


def mask(text):
    for p in PROVENANCE_TEXT:
        text = p.sub("", text)
    return [TIMING_TEXT.sub("<time>", line) for line in text.splitlines()]


def compare_text(pa, pb, name, out):
    with open(pa, encoding="utf-8", errors="replace") as f:
        a = mask(f.read())
    with open(pb, encoding="utf-8", errors="replace") as f:
        b = mask(f.read())
    if len(a) != len(b):
        out.append(f"{name}: {len(a)} lines != {len(b)} lines")
    for i, (x, y) in enumerate(zip(a, b)):
        if x != y and x.split() == y.split():
            spacing["lines"] += 1
            continue
        if x != y and not same_numbers(" ".join(x.split()), " ".join(y.split())):
            col = next((k for k, (c, d) in enumerate(zip(x, y)) if c != d), min(len(x), len(y)))
            lo = max(0, col - 30)
            out.append(f"{name}:{i + 1}: …{x[lo:col + 40]!r} != …{y[lo:col + 40]!r}")


NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def same_numbers(x, y):
    """Lines equal but for numbers that agree to round-off (relative to the line's largest)."""
    if NUMBER.sub("#", x) != NUMBER.sub("#", y):
        return False
    na = [float(m.group(0)) for m in NUMBER.finditer(x)]
    nb = [float(m.group(0)) for m in NUMBER.finditer(y)]
    scale = max([abs(v) for v in na + nb] or [0.0])
    return all(close(p, q, scale) for p, q in zip(na, nb))


def files_of(root):
    found = set()
    for d, _, names in os.walk(root):
        for n in names:
            found.add(os.path.relpath(os.path.join(d, n), root))
    return found


def main(a_dir, b_dir):
    problems = []
    names = sorted(n[:-7] for n in os.listdir(a_dir) if n.endswith(".status"))
    for name in names:
        for suffix in (".status",):
            with open(os.path.join(a_dir, name + suffix)) as f1, open(os.path.join(b_dir, name + suffix)) as f2:
                if f1.read() != f2.read():
                    problems.append(f"{name}: exit status differs")
        ja, jb = load_json(os.path.join(a_dir, name + ".json")), load_json(os.path.join(b_dir, name + ".json"))
        if isinstance(ja, dict) and "not_json" in ja:  # a readable report on stdout
            compare_text(os.path.join(a_dir, name + ".json"), os.path.join(b_dir, name + ".json"), name, problems)
            continue
        out = []
        diff(strip(ja), strip(jb), name, out)
        problems += out
    fa, fb = files_of(os.path.join(a_dir, "files")), files_of(os.path.join(b_dir, "files"))
    for f in sorted(fa ^ fb):
        problems.append(f"files/{f}: only in {'first' if f in fa else 'second'}")
    for f in sorted(fa & fb):
        pa, pb = os.path.join(a_dir, "files", f), os.path.join(b_dir, "files", f)
        if f.endswith(".json"):
            out = []
            diff(strip(load_json(pa)), strip(load_json(pb)), "files/" + f, out)
            problems += out
        else:
            compare_text(pa, pb, "files/" + f, problems)
    for p in problems[:200]:
        print(p)
    rounding = (f"; {round_off['count']} numbers differ at round-off (worst {round_off['worst']:.1e} relative)"
                if round_off["count"] else "; every number bit-identical")
    if spacing["lines"]:
        rounding += f"; {spacing['lines']} lines of readable text differ only in spacing"
    print(f"compare-outputs: {len(names)} commands, {len(fa & fb)} files: "
          + ("identical up to timing fields" if not problems else f"{len(problems)} differences") + rounding)
    return 1 if problems else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: normalize_output.py RECORD_A RECORD_B")
    sys.exit(main(sys.argv[1], sys.argv[2]))
