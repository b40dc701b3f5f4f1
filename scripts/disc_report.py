#!/usr/bin/python3
"""Figure and report.html for `spinesim study disc-validation --out DIR`.

Reads DIR/disc_validation.json and writes DIR/plots/disc_paths.png and DIR/report.html: with the
nonlinear disc (--model nonlinear), each standard load case's load-motion path (force against
displacement in compression, moment against rotation in bending and torsion) beside the in-vitro
window of that quantity, drawn as the wedge of secant stiffnesses between the window's low and
high ends up to the standard load; then the table of every quantity, ours against in vitro. Any
error is one line on stderr and exit status 1; a missing tool exits 2.

    /usr/bin/python3 scripts/disc_report.py DIR

Needs python3-matplotlib (Debian package; scripts/install-deps.sh).
"""
import html
import os
import sys

from report_tools import (
    failer, load_summary, page_head, pyplot, report_main, secant_wedge, write_page)

fail = failer("disc report")
plt = pyplot(fail)

# Stiffness units of the targets → load units per motion unit of the paths.
TO_PATH_UNITS = {"kN/mm": 1000.0, "N m/deg": 1.0}


def paths_figure(s, d):
    """One panel per load case: our path and the in-vitro secant window."""
    rows = {r["quantity"]: r for r in s["rows"]}
    paths = s["paths"]
    columns = min(3, len(paths))
    rows_n = (len(paths) + columns - 1) // columns
    fig, axes = plt.subplots(rows_n, columns, figsize=(4.3 * columns, 3.8 * rows_n), squeeze=False)
    for ax in axes.flat[len(paths):]:
        ax.axis("off")
    for ax, p in zip(axes.flat, paths):
        load, motion = [0.0] + p["load"], [0.0] + p["motion"]
        ax.plot(motion, load, "o-", color="C0", ms=3, label="nonlinear FEM disc")
        row = rows.get(p["load_case"])
        if row is not None and row.get("units") in TO_PATH_UNITS:
            scale = TO_PATH_UNITS[row["units"]]
            top = max(load)
            lo, hi = row["low"] * scale, row["high"] * scale
            # The wedge between load = k·motion for k in [low, high], up to the standard load.
            secant_wedge(ax, top, lo, hi, f"in vitro {row['low']:g}-{row['high']:g} {row['units']}")
            ours = row.get("ours")
            verdict = row.get("verdict", "n/a")
            title = f"{p['load_case']}: {ours:.3g} {row['units']} ({verdict})" \
                if isinstance(ours, (int, float)) else f"{p['load_case']}: n/a"
        else:
            title = p["load_case"]
        ax.set_title(title, fontsize=10)
        ax.set_xlabel(f"plate motion along the load ({p['motion_units']})")
        ax.set_ylabel(f"load ({p['load_units'].replace('N m', 'N·m')})")
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
    fig.suptitle(f"{s['mesh']}, {s['material']}: {s['formulation']}", fontsize=10)
    fig.tight_layout()
    name = "disc_paths.png"
    fig.savefig(os.path.join(d, "plots", name), dpi=100)
    plt.close(fig)
    return name


def table_html(s):
    head = ("<table><tr><th>quantity</th><th>units</th><th>ours</th><th>in vitro</th>"
            "<th>window</th><th>verdict</th><th>tested as</th><th>source</th></tr>")
    body = []
    for r in s["rows"]:
        ours = r["ours"]
        ours_text = f"{ours:.3g}" if isinstance(ours, (int, float)) else "n/a"
        verdict = r["verdict"] if r["verdict"] != "n/a" else f"n/a ({r.get('note', '')})"
        cells = [r["quantity"], r["units"], ours_text, r["reported"],
                 f"{r['low']:g} - {r['high']:g}", verdict, r["tested_as"], r["source"]]
        body.append("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in cells) + "</tr>")
    return head + "".join(body) + "</table>"


def write_report(d):
    """The figure and report.html from DIR/disc_validation.json; the figures' names."""
    s = load_summary(d, "disc_validation.json")
    figures = [paths_figure(s, d)] if s.get("paths") else []
    title = f"The disc beside in-vitro tests: {s['mesh']}"
    parts = [page_head(title),
             f"<p>Material {html.escape(s['material'])}; {html.escape(s['formulation'])}; "
             f"{s['tets']} tets, {s['dofs']} DOF. Stiffness = load / plate motion at the "
             "standard load (500 N, 7.5 N·m), disc frame.</p>"]
    parts += [f"<figure><img src='plots/{n}' alt='{n}'><figcaption>Load against plate "
              "motion per increment; the shaded wedge spans the in-vitro window's secant "
              "stiffnesses.</figcaption></figure>" for n in figures]
    if not figures:
        parts.append("<p>The load paths need <code>--model nonlinear</code>.</p>")
    parts.append(table_html(s) + "</body></html>")
    write_page(d, parts, s.get("provenance"))
    return figures


def main(argv):
    return report_main(argv, __doc__, fail, write_report)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
