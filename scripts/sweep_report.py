#!/usr/bin/python3
"""Plots and report.html for `spinesim sweep PLAN --out DIR`.

Reads DIR/summary.json and writes DIR/plots/sweep.png (each output against each parameter, one
dot per point, failed points as crosses on the axis) and, for a Morris or Sobol plan,
DIR/plots/sensitivity.png (mu* x range, or the first and total indices, per output and
parameter, with their bootstrap intervals), for a plan with windows DIR/plots/uncertainty.png
(each parameter and output before and after weighting by the windows), and DIR/report.html with the points' table. Any error is one line on stderr and exit
status 1 (2 for a missing tool).

    /usr/bin/python3 scripts/sweep_report.py DIR

Needs python3-matplotlib (Debian package; scripts/install-deps.sh).
"""
import html
import sys

from report_tools import failer, load_summary, page_head, pyplot, report_main, write_page

fail = failer("sweep report")
plt = pyplot(fail)


def numeric(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def parameters_and_outputs(s):
    points = s["points"]
    params = sorted({k for p in points for k in p["values"]})
    outputs = sorted({k for p in points for k in (p.get("outputs") or {})})
    return points, params, outputs


def draw_points(s, d):
    """Each output against each parameter. One parameter: the outputs in rows of four panels;
    several: one row per output, one column per parameter. Names (a list of text values) keep
    the plan's order."""
    points, params, outputs = parameters_and_outputs(s)
    outputs = [o for o in outputs if any(numeric((p.get("outputs") or {}).get(o)) for p in points)]
    if not outputs:
        return None
    panels = [(o, name) for o in outputs for name in params]
    cols = min(4, len(outputs)) if len(params) == 1 else len(params)
    rows = (len(panels) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, squeeze=False, figsize=(4.2 * cols, 3.2 * rows))
    flat = [a for r in axes for a in r]
    for ax in flat[len(panels):]:
        ax.axis("off")
    for ax, (o, name) in zip(flat, panels):
        ok = [p for p in points if numeric((p.get("outputs") or {}).get(o))]
        xs = [p["values"][name] for p in ok]
        if all(numeric(x) for x in xs):
            ax.plot(xs, [p["outputs"][o] for p in ok], "o", ms=4, alpha=0.7)
        else:  # a list of names: one column of dots per name, in the points' order
            names = list(dict.fromkeys(str(p["values"][name]) for p in points))
            ax.plot([names.index(str(x)) for x in xs], [p["outputs"][o] for p in ok], "o",
                    ms=4, alpha=0.7)
            ax.set_xticks(range(len(names)), names, rotation=90 if len(names) > 6 else 0,
                          fontsize=7 if len(names) > 6 else 9)
        failed = [p for p in points if p["status"] != "ok" and numeric(p["values"][name])]
        if failed:
            ax.plot([p["values"][name] for p in failed], [ax.get_ylim()[0]] * len(failed),
                    "x", color="C3", label="failed point")
            ax.legend(fontsize=8)
        win = ((s.get("uncertainty") or {}).get("windows") or {}).get(o)
        if win:
            ax.axhspan(win["low"], win["high"], color="C2", alpha=0.12)
        ax.set_xlabel(name)
        ax.set_ylabel(o, fontsize=9)
        ax.grid(alpha=0.3)
    fig.suptitle(f"{s['verb']}: {len(points)} points of {s['plan']}")
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    fig.savefig(f"{d}/plots/sweep.png", dpi=90)
    plt.close(fig)
    return "sweep.png"


def draw_sensitivity(s, d):
    sens = s.get("sensitivity")
    if not sens:
        return None
    outs = {o: e for o, e in sens["outputs"].items() if "error" not in e}
    if not outs:
        return None
    morris = sens["method"].startswith("Morris")
    cols = min(3, len(outs))
    rows = (len(outs) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, squeeze=False, figsize=(4.8 * cols, 3.4 * rows))
    for ax in [a for r in axes for a in r][len(outs):]:
        ax.axis("off")
    def bars(ax, x, e, names, key, **kw):
        """Bars of e[n][key] with their bootstrap intervals as error bars (when the summary
        has them)."""
        v = [e[n][key] for n in names]
        lo = [e[n].get(key + "_interval", [None, None])[0] for n in names]
        hi = [e[n].get(key + "_interval", [None, None])[1] for n in names]
        err = None
        if all(numeric(a) and numeric(b) for a, b in zip(lo, hi)):
            err = [[max(0, a - b) for a, b in zip(v, lo)], [max(0, b - a) for a, b in zip(v, hi)]]
        ax.bar(x, v, kw.pop("width", 0.8), yerr=err, capsize=3, **kw)
        return v + [b for b in hi if numeric(b)] + [a for a in lo if numeric(a)]

    for ax, (o, e) in zip([a for r in axes for a in r], sorted(outs.items())):
        names = sorted(e)
        x = list(range(len(names)))
        if morris:
            bars(ax, x, e, names, "mu_star_over_range", color="C0")
            ax.set_ylabel("mu* x range (output units)")
        else:
            values = bars(ax, [i - 0.2 for i in x], e, names, "first", width=0.4,
                          label="first S_i")
            values += bars(ax, [i + 0.2 for i in x], e, names, "total", width=0.4,
                           label="total S_Ti")
            ax.set_ylim(min(0, *values) - 0.05, max(1, *values) + 0.05)
            ax.legend(fontsize=8)
        ax.set_xticks(x, names, rotation=20 if len(names) > 3 else 0, fontsize=8)
        ax.set_title(o, fontsize=10)
        ax.grid(alpha=0.3, axis="y")
    title = f"{sens['method']}, {sens['runs']} runs"
    if "bootstrap" in sens:
        b = sens["bootstrap"]
        title += f"; bars: {round(100 * b['confidence'])} % bootstrap intervals"
    if not morris:  # N base points of Saltelli's N (k + 2) runs: the Monte Carlo error ~ 1/sqrt(N)
        n = sens["runs"] // (len(next(iter(outs.values()))) + 2)
        title += f" (N = {n}: the estimates scatter by about {1 / n ** 0.5:.2f})"
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    fig.savefig(f"{d}/plots/sensitivity.png", dpi=90)
    plt.close(fig)
    return "sensitivity.png"


def draw_uncertainty(s, d):
    """Each parameter and output: its values over the sample (the prior) and weighted by the
    windows (the posterior), as histograms, with the window shaded."""
    u = s.get("uncertainty")
    if not u or "error" in u:
        return None
    points, weights = s["points"], u["weights"]
    names = [("parameter", n) for n in sorted(u["parameters"])] + \
            [("output", n) for n in sorted(u["outputs"])]
    names = [(k, n) for k, n in names
             if "error" not in (u["parameters"] if k == "parameter" else u["outputs"])[n]]
    if not names:
        return None
    cols = min(4, len(names))
    rows = (len(names) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, squeeze=False, figsize=(4.2 * cols, 3.0 * rows))
    for ax, (kind, name) in zip([a for r in axes for a in r], names):
        v, w = [], []
        for p, wt in zip(points, weights):
            x = p["values"].get(name) if kind == "parameter" else (p.get("outputs") or {}).get(name)
            if numeric(x) and p["status"] == "ok":
                v.append(x)
                w.append(wt)
        if not v:
            continue
        used = [1.0 if wt > 0 else 0.0 for wt in w]
        bins = 20
        ax.hist(v, bins=bins, weights=[x / max(1, sum(used)) for x in used], alpha=0.45,
                color="C7", label="prior (the sample)")
        ax.hist(v, bins=bins, weights=w, alpha=0.7, color="C0", label="posterior (weighted)")
        if kind == "output" and name in u["windows"]:
            win = u["windows"][name]
            ax.axvspan(win["low"], win["high"], color="C2", alpha=0.15, label="window")
        ax.set_title(name, fontsize=9)
        ax.set_ylabel("weight")
        ax.grid(alpha=0.3)
    for ax in [a for r in axes for a in r][len(names):]:
        ax.axis("off")
    axes[0][0].legend(fontsize=7)
    fig.suptitle(f"Uncertainty: {u['points_used']} of {u['points']} points weighted by the windows; "
                 f"effective sample size {u['effective_sample_size']:.1f}")
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    fig.savefig(f"{d}/plots/uncertainty.png", dpi=90)
    plt.close(fig)
    return "uncertainty.png"


def table(s):
    points, params, outputs = parameters_and_outputs(s)
    head = "".join(f"<th>{html.escape(h)}</th>" for h in ["point", *params, "status", *outputs])
    rows = []
    for p in points[:200]:
        cells = [str(p["point"]), *[str(p["values"].get(n, "")) for n in params],
                 p["status"] if p["status"] == "ok" else f"{p['status']}: {p.get('error', '')}",
                 *[f"{v:.6g}" if numeric(v) else str(v if v is not None else "")
                   for v in [(p.get("outputs") or {}).get(o) for o in outputs]]]
        rows.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>")
    more = f"<p>… and {len(points) - 200} more in summary.csv.</p>" if len(points) > 200 else ""
    return f"<table><tr>{head}</tr>{''.join(rows)}</table>{more}"


def write_report(d):
    s = load_summary(d, "summary.json")
    figures = [f for f in (draw_points(s, d), draw_sensitivity(s, d), draw_uncertainty(s, d)) if f]
    points = s["points"]
    ok = sum(p["status"] == "ok" for p in points)
    p = s["provenance"]
    parts = [page_head(f"Sweep: {s['plan']}", 1200),
             f"<p>{len(points)} points of <code>{html.escape(s['verb'])}</code>: {ok} ok, "
             f"{len(points) - ok} failed.</p>",
             *[f"<figure><img src='plots/{f}' alt='{f}'></figure>" for f in figures],
             table(s),
             f"<footer><h2>Provenance</h2><p>{html.escape(p['program'])} "
             f"{html.escape(p['version'])} (commit <code>{html.escape(p['commit'])}</code>), "
             f"plan SHA-256 <code>{html.escape(p['plan_sha256'])}</code>; each point's own "
             "provenance is in its points/NNNN/result.json.</p></footer></body></html>"]
    write_page(d, parts)
    return figures


if __name__ == "__main__":
    sys.exit(report_main(sys.argv, __doc__, fail, write_report))
