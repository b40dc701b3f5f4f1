#!/usr/bin/python3
"""Figure and report.html for `spinesim study mss-fibres --out DIR`.

Reads DIR/mss_fibres.json and writes DIR/plots/mss_fibres_curves.png and DIR/report.html: one
panel per moment case — the nonlinear FEM disc's moment against rotation, the two fitted spring
networks (without and with fibre springs) at the FEM's poses, and the in-vitro window of that
case's stiffness drawn as the wedge of its secant stiffnesses up to the largest moment; then the
table of errors per case and load level. Any error is one line on stderr and exit status 1; a
missing tool exits 2.

    /usr/bin/python3 scripts/mss_fibres_report.py DIR

Needs python3-matplotlib (Debian package; scripts/install-deps.sh).
"""
import html
import os
import sys

from report_tools import (
    failer, load_summary, page_head, pyplot, report_main, secant_wedge, write_page)

fail = failer("mss-fibres report")
plt = pyplot(fail)


def curves_figure(s, d):
    """One panel per moment case: FEM, both networks, the in-vitro corridor."""
    corridors = {c["quantity"]: c for c in s.get("corridors", [])}
    curves = s["curves"]
    columns = min(2, len(curves))
    rows_n = (len(curves) + columns - 1) // columns
    fig, axes = plt.subplots(rows_n, columns, figsize=(5.2 * columns, 4.0 * rows_n),
                             squeeze=False)
    for ax in axes.flat[len(curves):]:
        ax.axis("off")
    for ax, c in zip(axes.flat, curves):
        rotation = [0.0] + c["rotation_deg"]
        ax.plot(rotation, [0.0] + c["fem_moment_nm"], "o-", color="black", ms=4,
                label="nonlinear FEM disc")
        ax.plot(rotation, [0.0] + c["region_moment_nm"], "s--", color="C0", ms=3,
                label="MSS, region scales")
        ax.plot(rotation, [0.0] + c["fibre_moment_nm"], "^-", color="C3", ms=3,
                label="MSS with fibre springs")
        corridor = corridors.get(c["case"])
        if corridor is not None:
            top = max(max(c["fem_moment_nm"]), 0.0)
            lo, hi = corridor["low"], corridor["high"]
            secant_wedge(ax, top, lo, hi, f"in vitro {lo:g}-{hi:g} N·m/°", alpha=0.2)
        ax.set_title(f"{c['case']} ({c['set']})", fontsize=10)
        ax.set_xlabel("rotation about the moment's axis (°)")
        ax.set_ylabel("moment (N·m)")
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="lower right")
    fig.suptitle(f"{s['mesh']}, {s['material']}, FEM P{s['fem_order']}: "
                 "the spring networks at the FEM's poses", fontsize=10)
    fig.tight_layout()
    name = "mss_fibres_curves.png"
    fig.savefig(os.path.join(d, "plots", name), dpi=100)
    plt.close(fig)
    return name


def percent(v):
    return f"{100.0 * v:.1f} %" if isinstance(v, (int, float)) else "n/a"


def errors_html(s):
    head = ("<table><tr><th>case</th><th>load</th><th>set</th><th>region reaction</th>"
            "<th>region displ.</th><th>fibre reaction</th><th>fibre displ.</th></tr>")
    body = []
    for g, f in zip(s["region"]["cases"], s["fibre"]["cases"]):
        cells = [f["case"], f"{f['level']:g}×", f["set"], percent(g["reaction_error"]),
                 percent(g["displacement_error"]), percent(f["reaction_error"]),
                 percent(f["displacement_error"])]
        body.append("<tr>" + "".join(f"<td>{html.escape(str(x))}</td>" for x in cells) + "</tr>")
    return head + "".join(body) + "</table>"


def fit_html(name, fit):
    scales = ", ".join(f"{k} {v:.3g}" for k, v in fit["scales"].items())
    bounds = "; at bounds: " + ", ".join(fit["active_bounds"]) if fit["active_bounds"] else ""
    return (f"<p><b>{html.escape(name)}</b>: {html.escape(fit['status'])}, "
            f"{fit['iterations']} Ipopt iterations, {fit['model_evaluations']} MSS solves, "
            f"{fit['seconds']:.0f} s; scales {html.escape(scales)}{html.escape(bounds)}.</p>")


def write_report(d):
    """The figure and report.html from DIR/mss_fibres.json; the figures' names."""
    s = load_summary(d, "mss_fibres.json")
    figures = [curves_figure(s, d)] if s.get("curves") else []
    title = f"The mass-spring disc against the nonlinear FEM disc: {s['mesh']}"
    parts = [page_head(title),
             f"<p>Material {html.escape(s['material'])}; FEM P{s['fem_order']}; network terms "
             f"{html.escape(s.get('terms', 'n/a'))}; {s['nodes']} "
             f"nodes, {s['tets']} tets, {s['fibre_springs']} fibre springs. Each network's "
             "superior plate is moved to the FEM's pose; reaction error |S ΔR|/|S R*|, "
             "displacement error ‖Δu‖/‖u*‖ over the free vertices.</p>"]
    parts += [f"<figure><img src='plots/{n}' alt='{n}'><figcaption>Moment against rotation "
              "along the applied moment: the FEM loaded by the moment, the networks moved to "
              "the FEM's pose at each point (so they share its rotation and its off-axis "
              "motion); the shaded wedge spans the in-vitro window's secant stiffnesses."
              "</figcaption></figure>" for n in figures]
    if not figures:
        parts.append("<p>No moment case among the cases, or no curve levels: no curves.</p>")
    parts.append(errors_html(s))
    parts.append(fit_html("Region network", s["region"]) + fit_html("Fibre network", s["fibre"]))
    sources = "".join(f"<li>{html.escape(c['quantity'])}: {html.escape(c['reported'])} "
                      f"({html.escape(c['preparation'])}); {html.escape(c['source'])}</li>"
                      for c in s.get("corridors", []))
    if sources:
        parts.append(f"<p>In-vitro windows:</p><ul>{sources}</ul>")
    parts.append("</body></html>")
    write_page(d, parts, s.get("provenance"))
    return figures


def main(argv):
    return report_main(argv, __doc__, fail, write_report)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
