#!/usr/bin/python3
"""Plots and report.html for `spinesim demo`.

Reads what the demo wrote in DIR (summary.json, report.md, haptic_plane.csv, haptics_stroke.csv,
spine_trends.csv, spine_fusion.csv, probe/probe.csv)
and writes DIR/plots/*.png and DIR/report.html: each figure beside the caption of its counterpart
in the thesis and our numbers, then the text report. Any error is one line on stderr and exit
status 2 (report.md is left as it is).

    /usr/bin/python3 scripts/report.py DIR

Needs python3-matplotlib and python3-markdown (Debian packages; scripts/install-deps.sh).
"""
import csv
import html
import json
import os
import sys

from report_tools import failer, folder_argument, guarded, pyplot, write_page

fail = failer("report")
plt = pyplot(fail)

try:
    import markdown
except ImportError:
    fail("python3-markdown is missing (apt-get install python3-markdown)", 2)


class Figure:
    """One figure of the report: file name, title, the thesis counterpart and our numbers."""

    def __init__(self, name, title, thesis, ours):
        self.name, self.title, self.thesis, self.ours = name, title, thesis, ours


def read_csv(path, text_columns=()):
    """Rows of a CSV whose comment lines start with '#', as dicts of floats (but text_columns)."""
    with open(path, newline="") as f:
        lines = [line for line in f if not line.startswith("#")]
    rows = list(csv.DictReader(lines))
    if not rows:
        raise ValueError(f"{path}: no data rows")
    return [{k: (v if k in text_columns else float(v)) for k, v in r.items()} for r in rows]


def findings_text(study):
    """'n of m thesis findings reproduced (ids that differ: …)' from a study's findings."""
    f = study["findings"]
    differ = [x["id"] for x in f if not x["match"]]
    text = f"{len(f) - len(differ)} of {len(f)} thesis findings reproduced"
    return text + (f" (differ: {', '.join(differ)})" if differ else "")


def save(fig, out_dir, name):
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "plots", name), dpi=110)
    plt.close(fig)


def haptic_plane(d, out_dir):
    rows = read_csv(os.path.join(d, "haptic_plane.csv"))
    depth = [r["depth_mm"] for r in rows]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for ax, eq, unit in ((axes[0], "eq49", "eq 4.9 (sum over sample points)"),
                         (axes[1], "eq410", "eq 4.10 (normalised, improved)")):
        for probe, colour in (("small", "tab:blue"), ("large", "tab:red")):
            radius = 5 if probe == "small" else 10
            ax.plot(depth, [r[f"{probe}_{eq}_n"] for r in rows], color=colour,
                    label=f"r = {radius} mm, sampled")
            ax.plot(depth, [r[f"{probe}_{eq}_exact_n"] for r in rows], color=colour,
                    linestyle="--", linewidth=0.8, label=f"r = {radius} mm, closed form")
        ax.set_xlabel("intrusion depth (mm)")
        ax.set_ylabel("force magnitude (N)")
        ax.set_title(unit)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    save(fig, out_dir, "haptic_plane.png")
    peak = max(rows, key=lambda r: r["small_eq49_n"])
    ratio49 = peak["large_eq49_n"] / peak["small_eq49_n"]
    ratio410 = peak["large_eq410_n"] / peak["small_eq410_n"]
    return Figure(
        "haptic_plane.png", "Gao–Gibson force against intrusion depth (probes through a plane)",
        "Figs 4.16, 4.18, 4.19: the force peaks at depth = radius; with eq 4.9 the larger probe "
        "is over twice as strong at the small probe's peak (\"over 40\" against \"less than 20\" "
        "units); with eq 4.10 both are \"nearly the same\" there.",
        f"small probe's peak at {peak['depth_mm']:.2f} mm; large/small there: eq 4.9 "
        f"{ratio49:.2f}, eq 4.10 {ratio410:.4f}.")


def probe_test(d, out_dir):
    rows = read_csv(os.path.join(d, "probe", "probe.csv"), text_columns=("site",))
    sites = list(dict.fromkeys(r["site"] for r in rows))
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for site in sites:
        run = [r for r in rows if r["site"] == site]
        t = [r["time_s"] for r in run]
        axes[0].plot(t, [r["force_n"] for r in run], label=f"{site} wall")
        axes[1].plot(t, [100 * r["volume_change"] for r in run], label=f"{site} wall")
    axes[0].set_ylabel("probe force (N)")
    axes[1].set_ylabel("disc volume change (%)")
    for ax in axes:
        ax.set_xlabel("time (s)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    save(fig, out_dir, "probe_test.png")
    dv = min(r["volume_change"] for r in rows)
    depth = max(r["depth_mm"] for r in rows)
    return Figure(
        "probe_test.png", "A rigid probe pressed into the disc wall (the untuned MSS disc)",
        "Fig 5.8 (test 1 of ch. 5.3): the disc deforms consistently and its volume is preserved "
        "under continuous deformation (pictures; no numbers).",
        f"pressed {depth:.1f} mm at {len(sites)} sites: peak force "
        f"{max(r['force_n'] for r in rows):.1f} N, volume change down to {100 * dv:.3f} %.")


def calibration(s, out_dir):
    c = s["calibration"]
    cases = [(r["name"], "train", r) for r in c["train"]] + \
            [(r["name"], "held out", r) for r in c["holdout"]]
    names = [f"{n}\n({kind})" for n, kind, _ in cases]
    before = [100 * r["untuned_error"] for _, _, r in cases]
    after = [100 * r["tuned_error"] for _, _, r in cases]
    fig, ax = plt.subplots(figsize=(10, 3.8))
    x = range(len(cases))
    ax.bar([i - 0.2 for i in x], before, 0.4, label="thesis constants (untuned)", color="0.6")
    ax.bar([i + 0.2 for i in x], after, 0.4, label="tuned (Ipopt)", color="tab:green")
    ax.set_xticks(list(x))
    ax.set_xticklabels(names, fontsize=8)
    ax.set_ylabel("MSS displacement error vs FEM (%)")
    ax.grid(axis="y", alpha=0.3)
    ax.legend()
    save(fig, out_dir, "calibration.png")
    held = [r for _, kind, r in cases if kind == "held out"]
    worst = max(held, key=lambda r: r["tuned_error"])
    return Figure(
        "calibration.png", f"MSS against FEM, before and after tuning ({s['level']})",
        "Ch. 5.3: the thesis sets the spring constants from the material (eqs 5.1–5.8) and "
        "shows the disc compressing (fig 5.9); it never compares the MSS with an FE reference.",
        f"mean error {sum(before) / len(before):.1f} % untuned → {sum(after) / len(after):.1f} % "
        f"tuned; worst held-out case {worst['name']} {100 * worst['tuned_error']:.1f} %.")


def materials(s, out_dir):
    m = s["materials"]
    # Two-word presets on two lines, so five names fit under the bars.
    names = [r["material"].replace("-", "-\n", 1) for r in m]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    x = range(len(m))
    axes[0].bar([i - 0.2 for i in x], [100 * r["untuned"]["displacement_error"] for r in m], 0.4,
                label="untuned", color="0.6")
    axes[0].bar([i + 0.2 for i in x], [100 * r["tuned"]["displacement_error"] for r in m], 0.4,
                label="tuned", color="tab:green")
    axes[0].set_ylabel("MSS displacement error vs FEM (%)")
    axes[0].set_title("compression")
    axes[0].legend()
    for k, (key, label, colour) in enumerate((("fem", "FEM", "tab:blue"),
                                              ("untuned", "MSS untuned", "0.6"),
                                              ("tuned", "MSS tuned", "tab:green"))):
        axes[1].bar([i + (k - 1) * 0.27 for i in x], [r[key]["axial_stiffness_n_per_mm"] for r in m],
                    0.27, label=label, color=colour)
    axes[1].set_yscale("log")
    axes[1].set_ylabel("axial stiffness (N/mm)")
    axes[1].legend(fontsize=8)
    for ax in axes:
        ax.set_xticks(list(x))
        ax.set_xticklabels(names, fontsize=8)
        ax.grid(axis="y", alpha=0.3)
    save(fig, out_dir, "materials.png")
    return Figure(
        "materials.png", "The materials study: each preset's disc, FEM and MSS",
        "Fig 5.9: disc compression with different materials (pictures of the deformed MSS disc; "
        "no numbers).",
        "; ".join(f"{r['material']}: FEM {r['fem']['axial_stiffness_n_per_mm']:.0f} N/mm, tuned "
                  f"MSS error {100 * r['tuned']['displacement_error']:.1f} %" for r in m) + ".")


def validation(s, out_dir):
    v = s["spine_validation"]
    mc, wi = v["mcgill"], v["wilke"]
    windows = [
        ("L5-S1 axial, lifting\n(McGill & Norman)", mc["axial_n"], mc["target"]["axial_range_n"],
         mc["thesis"]["axial_n"]),
        ("L5-S1 shear, lifting\n(McGill & Norman)", mc["shear_n"], [0, mc["target"]["shear_max_n"]],
         mc["thesis"]["shear_n"]),
        ("L4-L5 axial, crate\n(Wilke et al.)", wi["axial_n"], wi["target"]["axial_range_n"],
         wi["thesis"]["axial_n"]),
    ]
    fig, ax = plt.subplots(figsize=(10, 3.8))
    for i, (label, ours, band, thesis) in enumerate(windows):
        ax.add_patch(plt.Rectangle((i - 0.4, band[0]), 0.8, band[1] - band[0], color="tab:green",
                                   alpha=0.2, label="target window" if i == 0 else None))
        ax.bar(i - 0.15, ours, 0.3, color="tab:blue", label="ours" if i == 0 else None)
        ax.bar(i + 0.15, thesis, 0.3, color="0.6", label="thesis" if i == 0 else None)
    ax.set_xticks(range(len(windows)))
    ax.set_xticklabels([w[0] for w in windows], fontsize=8)
    ax.set_ylabel("force (N)")
    ax.set_xlim(-0.6, len(windows) - 0.4)
    ax.grid(axis="y", alpha=0.3)
    ax.legend()
    save(fig, out_dir, "validation.png")
    verdict = "inside" if v["pass"] else "outside"
    return Figure(
        "validation.png", "The spine's validation windows",
        "Ch. 3.4: 1,260 N on T7 gives 4,582 N axial and 625 N shear at L5-S1 (McGill & Norman's "
        "lift); the crate held in front of the chest loads L4-L5 with 3,162 N (Wilke et al.).",
        f"{mc['axial_n']:.0f} N axial / {mc['shear_n']:.0f} N shear at L5-S1 and {wi['axial_n']:.0f} N "
        f"at L4-L5: {verdict} every window.")


def spine_t1(d, s, out_dir):
    rows = read_csv(os.path.join(d, "spine_trends.csv"), text_columns=("load", "pair"))
    loads = list(dict.fromkeys(r["load"] for r in rows))
    fig, axes = plt.subplots(2, len(loads), figsize=(12, 6.5), sharex=True)
    for j, load in enumerate(loads):
        run = [r for r in rows if r["load"] == load]
        pairs = [r["pair"] for r in run]
        for i, (keys, unit) in enumerate(((("dx_mm", "dy_mm", "dz_mm"), "relative translation (mm)"),
                                          (("theta_x_deg", "theta_y_deg", "theta_z_deg"),
                                           "relative rotation (deg)"))):
            ax = axes[i][j]
            for key, axis, colour in zip(keys, "xyz", ("tab:red", "tab:green", "tab:blue")):
                ax.plot(range(len(run)), [r[key] for r in run], marker="o", markersize=3,
                        color=colour, label=f"{axis}")
            ax.axhline(0, color="0.5", linewidth=0.6)
            ax.grid(alpha=0.3)
            if j == 0:
                ax.set_ylabel(unit)
            if i == 0:
                ax.set_title(f"{load} force on T1")
            ax.set_xticks(range(len(run)))
            ax.set_xticklabels(pairs, rotation=90, fontsize=7)
        axes[0][j].legend(fontsize=8, title="axis", title_fontsize=8)
    save(fig, out_dir, "spine_t1.png")
    force = s["spine_trends"].get("force_n", 300)
    return Figure(
        "spine_t1.png", f"Every vertebra pair under a {force:.0f} N force on T1 (upper minus lower)",
        "Figs 6.12–6.25 (x, y, z relative translations of the pairs T1–T9 and T9–L5 under "
        "lateral, forward and backward force on T1) and 6.38–6.47 (relative rotations).",
        findings_text(s["spine_trends"]) + ".")


def fusion(d, s, out_dir):
    rows = read_csv(os.path.join(d, "spine_fusion.csv"), text_columns=("fusion", "load"))
    fusions = list(dict.fromkeys(r["fusion"] for r in rows))
    loads = list(dict.fromkeys(r["load"] for r in rows))
    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    width = 0.8 / len(fusions)
    for k, name in enumerate(fusions):
        axes[0].bar([i + (k - (len(fusions) - 1) / 2) * width for i in range(len(loads))],
                    [next(r["t1_translation_mm"] for r in rows
                          if r["fusion"] == name and r["load"] == load) for load in loads],
                    width, label=name)
    axes[0].set_xticks(range(len(loads)))
    axes[0].set_xticklabels([f"{load} force" for load in loads])
    axes[0].set_ylabel("T1 translation by the force (mm)")
    axes[0].legend(fontsize=8, title="fusion", title_fontsize=8)
    joints = (("l2l3_resultant_n", "L2-L3"), ("l5s1_resultant_n", "L5-S1"))
    forward = [r for r in rows if r["load"] == loads[0]]
    for k, name in enumerate(fusions):
        r = next(x for x in forward if x["fusion"] == name)
        axes[1].bar([i + (k - (len(fusions) - 1) / 2) * width for i in range(len(joints))],
                    [r[key] for key, _ in joints], width, label=name)
    axes[1].set_xticks(range(len(joints)))
    axes[1].set_xticklabels([f"{label} ({loads[0]} force)" for _, label in joints])
    axes[1].set_ylabel("joint force, resultant (N)")
    for ax in axes:
        ax.grid(axis="y", alpha=0.3)
    save(fig, out_dir, "fusion.png")
    return Figure(
        "fusion.png", "Spinal fusion at L3-L4, L4-L5 and L3-L4-L5 against the normal spine",
        "Figs 6.1–6.3: the fused spines move T1 less than the normal one, L3-L4 less than "
        "L4-L5, L3-L4-L5 least; figs 6.4–6.6: the forces on the joints next to a fusion rise.",
        findings_text(s["spine_fusion"]) + ".")


def haptic_stroke(d, out_dir):
    rows = read_csv(os.path.join(d, "haptics_stroke.csv"))
    t = [r["t_s"] for r in rows]
    f = [(r["fx_n"] ** 2 + r["fy_n"] ** 2 + r["fz_n"] ** 2) ** 0.5 for r in rows]
    fig, ax = plt.subplots(figsize=(10, 3.2))
    ax.plot(t, f, linewidth=0.8)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("|force| on the hand (N)")
    ax.grid(alpha=0.3)
    save(fig, out_dir, "haptic_stroke.png")
    contact = sum(r["contact"] > 0 for r in rows)
    return Figure(
        "haptic_stroke.png", "The simulated hand strokes the spinous processes (1 kHz loop)",
        "Ch. 4.5 and 6.3: the thesis's users touched the spine in the haptic loop; it shows no "
        "force record.",
        f"{len(rows)} ticks, {contact} in contact, peak {max(f):.2f} N.")


def viewer_screenshots(d):
    """The viewer's pictures the demo took (DIR/viewer.json, PNGs in DIR/plots/), if any."""
    path = os.path.join(d, "viewer.json")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        shots = json.load(f)
    return [Figure(x["file"], x["title"], x["thesis"], x["ours"]) for x in shots
            if os.path.exists(os.path.join(d, "plots", x["file"]))]


def write_html(d, figures, report_md):
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>spinesim demo report</title>",
             "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em}"
             "figure{margin:2em 0;border-top:1px solid #ccc;padding-top:1em}img{max-width:100%}"
             ".thesis{color:#555}table{border-collapse:collapse}td,th{border:1px solid #ccc;"
             "padding:2px 6px}pre{background:#f6f6f6;padding:0.5em;overflow-x:auto}</style>",
             "</head><body><h1>spinesim demo report</h1><h2>Figures</h2>"]
    for f in figures:
        parts.append(f"<figure><h3>{html.escape(f.title)}</h3>"
                     f"<img src='plots/{f.name}' alt='{html.escape(f.title)}'>"
                     f"<figcaption><p class='thesis'><b>Thesis:</b> {html.escape(f.thesis)}</p>"
                     f"<p><b>Ours:</b> {html.escape(f.ours)}</p></figcaption></figure>")
    parts.append("<h2>Text report</h2>")
    parts.append(markdown.markdown(report_md, extensions=["tables", "fenced_code"]))
    parts.append("</body></html>")
    write_page(d, parts)


def figures_and_html(d, s, report_md):
    """Every figure, then report.html; the figures' names."""
    figures = []
    figures.append(haptic_plane(d, d))
    figures.append(probe_test(d, d))
    figures.append(calibration(s, d))
    figures.append(materials(s, d))
    figures.append(validation(s, d))
    figures.append(spine_t1(d, s, d))
    figures.append(fusion(d, s, d))
    figures.append(haptic_stroke(d, d))
    figures += viewer_screenshots(d)
    write_html(d, figures, report_md)
    return figures


def main(argv):
    d = folder_argument(argv, __doc__)
    summary_path = os.path.join(d, "summary.json")
    try:
        with open(summary_path) as f:
            s = json.load(f)
        with open(os.path.join(d, "report.md")) as f:
            report_md = f.read()
    except (OSError, ValueError) as e:
        fail(f"cannot read the demo's output in {d}: {e}")
    os.makedirs(os.path.join(d, "plots"), exist_ok=True)
    figures = guarded(fail, d, lambda: figures_and_html(d, s, report_md))
    print(f"report: {os.path.join(d, 'report.html')} with {len(figures)} figures in "
          f"{os.path.join(d, 'plots')}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
