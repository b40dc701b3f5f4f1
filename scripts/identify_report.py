#!/usr/bin/python3
"""Figure and report.html for `spinesim study disc-identify --out DIR`.

Reads DIR/disc_identification.json and writes DIR/plots/disc_identification.png and
DIR/report.html: left, each in-vitro quantity over its window's geometric centre (log scale) —
the window shaded, the preset, the identified disc and the leave-one-out prediction marked, the
held-out windows of the same quantity dashed; right, each parameter's place between its bounds
(log scale) at the start and at the end, so an active bound shows at a glance. Then the tables.
Any error is one line on stderr and exit status 1; a missing tool exits 2.

    /usr/bin/python3 scripts/identify_report.py DIR

Needs python3-matplotlib (Debian package; scripts/install-deps.sh).
"""
import html
import math
import os
import sys

from report_tools import failer, load_summary, page_head, pyplot, report_main, write_page

fail = failer("identification report")
plt = pyplot(fail)


def quantities_panel(ax, s):
    rows = s["targets"]
    held = {}
    for h in s.get("held_out", []):
        held.setdefault(h["quantity"], []).append(h)
    for y, r in enumerate(rows):
        centre = math.sqrt(r["low"] * r["high"])
        ax.fill_betweenx([y - 0.3, y + 0.3], r["low"] / centre, r["high"] / centre, color="C2",
                         alpha=0.25, label="in-vitro window" if y == 0 else None)
        for k, h in enumerate(held.get(r["quantity"], [])):
            ax.plot([h["low"] / centre, h["high"] / centre], [y + 0.38] * 2, "--", color="C3",
                    lw=1.5, label="held-out window" if not any(
                        l.get_label() == "held-out window" for l in ax.lines) else None)
        for key, style, label in (("preset", dict(marker="s", color="0.5"), "preset"),
                                  ("identified", dict(marker="o", color="C0"), "identified"),
                                  ("leave_one_out", dict(marker="x", color="C1"),
                                   "leave-one-out prediction")):
            v = r.get(key)
            if isinstance(v, (int, float)) and v > 0:
                ax.plot([v / centre], [y], ls="none", ms=7, **style,
                        label=label if y == 0 else None)
    ax.set_xscale("log")
    ticks = [t for t in (0.125, 0.25, 0.5, 1, 2, 4, 8) if ax.get_xlim()[0] <= t <= ax.get_xlim()[1]]
    ax.set_xticks(ticks)
    ax.set_xticklabels([f"{t:g}" for t in ticks])
    ax.minorticks_off()
    ax.axvline(1.0, color="0.7", lw=0.8)
    ax.set_yticks(range(len(rows)))
    ax.set_yticklabels([f"{r['quantity']} ({r['units']})" for r in rows], fontsize=9)
    ax.invert_yaxis()
    ax.set_xlabel("value / window centre (log)")
    ax.grid(alpha=0.3, axis="x")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3)
    ax.set_title("in-vitro quantities", fontsize=10)


def parameters_panel(ax, s):
    params = s["parameters"]
    for y, p in enumerate(params):
        span = math.log(p["upper"] / p["lower"])
        place = lambda v: math.log(v / p["lower"]) / span
        ax.plot([0, 1], [y, y], color="0.6", lw=6, alpha=0.4, solid_capstyle="butt")
        ax.plot([place(p["start"])], [y], "s", color="0.5", ms=7,
                label="start" if y == 0 else None)
        ax.plot([place(p["identified"])], [y], "o", color="C0", ms=7,
                label="identified" if y == 0 else None)
        for v in p.get("leave_one_out", []):
            ax.plot([place(v)], [y + 0.15], "x", color="C1", ms=5)
        ax.text(0.0, y + 0.4, f"{p['lower']:g}", ha="center", fontsize=7)
        ax.text(1.0, y + 0.4, f"{p['upper']:g}", ha="center", fontsize=7)
    ax.set_yticks(range(len(params)))
    ax.set_yticklabels([p["name"] + (f" ({p['units']})" if p["units"] else "") for p in params],
                       fontsize=9)
    ax.set_xlim(-0.08, 1.08)
    ax.set_xticks([0, 1])
    ax.set_xticklabels(["lower bound", "upper bound"])
    ax.set_ylim(len(params) - 0.4, -0.6)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    ax.set_title("parameters between their bounds (log); x: leave-one-out fits", fontsize=10)


def figure(s, d):
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5.2),
                                      gridspec_kw={"width_ratios": [1.4, 1]})
    quantities_panel(left, s)
    parameters_panel(right, s)
    fig.suptitle(f"Identified from '{s['material']}': {s['status']} — values on {s['fine_disc']}",
                 fontsize=10)
    fig.tight_layout()
    name = "disc_identification.png"
    fig.savefig(os.path.join(d, "plots", name), dpi=100)
    plt.close(fig)
    return name


def table(header, rows):
    head = "<tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header) + "</tr>"
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table>{head}{body}</table>"


def number(v):
    return f"{v:.3g}" if isinstance(v, (int, float)) else "n/a"


def verdict(v, r):
    if not isinstance(v, (int, float)):
        return "n/a"
    return "MATCH" if r["low"] <= v <= r["high"] else "MISS"


def write_report(d):
    s = load_summary(d, "disc_identification.json")
    name = figure(s, d)
    title = "The disc material identified from in-vitro tests"
    parts = [page_head(title),
             f"<p>Start: {html.escape(s['material'])}. Fitted on {html.escape(s['coarse_disc'])}, "
             f"corrected to and reported on {html.escape(s['fine_disc'])}. "
             f"{html.escape(s['status'])}. Active bounds: "
             f"{html.escape(', '.join(s['active_bounds']) or 'none')}.</p>",
             f"<figure><img src='plots/{name}' alt='{name}'></figure>",
             "<h2>Parameters</h2>",
             table(["parameter", "units", "start", "lower", "upper", "identified",
                    "source of the bounds"],
                   [[p["name"], p["units"], number(p["start"]), number(p["lower"]),
                     number(p["upper"]), number(p["identified"]), p["bounds_source"]]
                    for p in s["parameters"]]),
             "<h2>In-vitro quantities</h2>",
             table(["quantity", "units", "window", "preset", "identified", "verdict",
                    "leave-one-out", "verdict", "tested as", "source"],
                   [[r["quantity"], r["units"], f"{r['low']:g} - {r['high']:g}",
                     number(r["preset"]), number(r["identified"]), verdict(r["identified"], r),
                     number(r["leave_one_out"]), verdict(r["leave_one_out"], r),
                     r["preparation"], r["source"]] for r in s["targets"]]),
             "<h2>Held out (predicted, not fitted)</h2>",
             table(["quantity", "units", "window", "identified", "verdict", "source"],
                   [[r["quantity"], r["units"], f"{r['low']:g} - {r['high']:g}",
                     number(r["identified"]), verdict(r["identified"], r), r["source"]]
                    for r in s.get("held_out", [])]),
             "</body></html>"]
    write_page(d, parts, s.get("provenance"))
    return [name]


def main(argv):
    return report_main(argv, __doc__, fail, write_report)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
