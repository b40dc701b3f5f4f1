#!/usr/bin/python3
"""Plots and report.html for `spinesim spine schedule --out DIR`.

Reads DIR/schedule.json and writes DIR/plots/schedule.png and DIR/report.html: the scheduled
loads against time, the lumbar discs' compression and shear (L1-L2 ... L5-S1, joint frame) and
T1's motion (translation in mm, rotation in deg) over the same time axis. Steps without
equilibrium are gaps. Any error is one line on stderr and exit status 2.

    /usr/bin/python3 scripts/schedule_report.py DIR

Needs python3-matplotlib (Debian package; scripts/install-deps.sh).
"""
import html
import math
import sys

from report_tools import failer, load_summary, page_head, pyplot, report_main, write_page

fail = failer("schedule report")
plt = pyplot(fail)

LUMBAR = ["T12-L1", "L1-L2", "L2-L3", "L3-L4", "L4-L5", "L5-S1"]


def series(steps, value):
    """value(step) per step, NaN where the step reached no equilibrium (a gap in the line)."""
    return [value(s) if s["converged"] else math.nan for s in steps]


def draw(s, d):
    steps = s["steps"]
    t = [st["time_s"] for st in steps]
    fig, axes = plt.subplots(4, 1, figsize=(10, 11), sharex=True)
    # Forces (N) on the left axis, couples (N·mm) on the right: their sizes differ a thousandfold.
    couples = axes[0].twinx() if any(not c.endswith("_n") for c in s["columns"]) else None
    for i, c in enumerate(s["columns"]):
        force = c.endswith("_n")
        ax = axes[0] if force else couples
        ax.plot(t, [st["loads"][c] for st in steps], ".-" if force else ".--", color=f"C{i}",
                label=f"{c} ({'N' if force else 'N·mm, right axis'})")
    axes[0].set_ylabel("force (N)")
    if couples is not None:
        couples.set_ylabel("couple (N·mm)")
        couples.legend(fontsize=8, loc="lower right")
    axes[0].set_title("Scheduled loads (linear between the key times)")
    for k in s["key_times_s"]:
        axes[0].axvline(k, color="0.8", lw=0.8)
    for j in LUMBAR:
        axes[1].plot(t, series(steps, lambda st, j=j: st["joints"][j]["axial_n"]), ".-", label=j)
        axes[2].plot(t, series(steps, lambda st, j=j: st["joints"][j]["shear_ap_n"]), ".-",
                     label=j)
    axes[1].set_title("Disc compression, joint frame (N)")
    axes[2].set_title("Anteroposterior shear, joint frame (N; + the lower vertebra pushes forward)")
    names = ["tx (mm)", "ty (mm)", "tz (mm)", "rx (deg)", "ry (deg)", "rz (deg)"]
    for k, name in enumerate(names):
        axes[3].plot(t, series(steps, lambda st, k=k: st["t1_displacement"][k]),
                     ".-" if k < 3 else ".--", label=name)
    axes[3].set_title("T1's motion from the tables' reference posture (F.1)")
    motion = s.get("dynamic")
    if motion:  # the integrated motion beside the quasi-static answer (--dynamic)
        td = [m["time_s"] for m in motion["samples"]]
        axes[1].plot(td, [m["l4l5_axial_n"] for m in motion["samples"]], "k-", lw=1.5,
                     label="L4-L5, the motion")
        axes[3].plot(td, [m["t1_displacement"][2] for m in motion["samples"]], "k-", lw=1.5,
                     label="tz (mm), the motion")
    axes[3].set_xlabel("time (s)")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, ncol=3)
    fig.tight_layout()
    fig.savefig(f"{d}/plots/schedule.png", dpi=100)
    plt.close(fig)
    return "schedule.png"


def inertia_text(s):
    """The inertia check and, when integrated, the motion, as a paragraph."""
    i = s.get("inertia") or {}
    parts = []
    if i.get("first_frequency_hz") is not None:
        parts.append(f"The spine's first natural frequency is {i['first_frequency_hz']:.2f} Hz")
        if i.get("overshoot_bound") is not None:
            parts.append(f"the fastest ramp ({i['fastest_ramp_s']:.3f} s) may overshoot its "
                         f"quasi-static answer by up to {100 * i['overshoot_bound']:.1f} % "
                         "(undamped bound)")
    m = s.get("dynamic")
    if m:
        parts.append(f"the motion was integrated (Newmark, {1000 * m['dt_s']:.1f} ms steps, damping "
                     f"ratio {m['damping_ratio']:.2f}) and is drawn in black")
    return f"<p>{html.escape('; '.join(parts))}.</p>" if parts else ""


def write_report(d):
    s = load_summary(d, "schedule.json")
    figure = draw(s, d)
    b = s["subject"]
    title = f"Loads in time: {s['schedule']}"
    parts = [page_head(title, 1100),
             f"<p>{len(s['steps'])} quasi-static equilibria ({s['failed']} without one); body "
             f"{html.escape(b['sex'])}, {b['height_m']:.3f} m, {b['body_mass_kg']:.1f} kg.</p>",
             inertia_text(s),
             f"<figure><img src='plots/{figure}' alt='{figure}'></figure></body></html>"]
    write_page(d, parts, s.get("provenance"))
    return [figure]


if __name__ == "__main__":
    sys.exit(report_main(sys.argv, __doc__, fail, write_report))
