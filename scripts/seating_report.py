#!/usr/bin/python3
"""Plots and report.html for `spinesim study seating --out DIR` and `study seating-sweep --out DIR`.

Reads DIR/seating.json (one chair) or DIR/seating_sweep.json (a sweep) and writes DIR/plots/*.png
and DIR/report.html: for one chair the contact force between back and chair per level (thesis
fig. 6.7) and the L5-S1 force and moment in x, y, z (fig. 6.8) with the disc loads along the
spine; for a sweep the L4-L5 and L5-S1 compression, the back-muscle force and the backrest force
against the swept parameter. Any error is one line on stderr and exit status 2.

    /usr/bin/python3 scripts/seating_report.py DIR

Needs python3-matplotlib (Debian package; scripts/install-deps.sh).
"""
import html
import json
import os
import sys

from report_tools import failer, folder_argument, guarded, pyplot, write_page

fail = failer("seating report")
plt = pyplot(fail)


def save(fig, d, name):
    fig.tight_layout()
    fig.savefig(os.path.join(d, "plots", name), dpi=110)
    plt.close(fig)
    return name


def chair_text(s):
    c = s["chair"]
    if c["surface"]:
        back = f"backrest from {c['surface']}"
    elif c["backrest_height_mm"] <= 0:
        back = "no backrest"
    else:
        back = f"backrest {c['backrest_recline_deg']:g} deg"
        if c["lumbar_support_mm"] > 0:
            back += f", lumbar support {c['lumbar_support_mm']:g} mm"
    return f"{back}; seat {c['seat_angle_deg']:g} deg" + ("; armrests" if c["armrests"] else "")


def contacts(s, d):
    """Thesis fig. 6.7: contact force between the back and the chair, per level."""
    levels = [c["level"] for c in s["contacts"]]
    fy = [c["force_n"][1] for c in s["contacts"]]
    fz = [c["force_n"][2] for c in s["contacts"]]
    fig, ax = plt.subplots(figsize=(9, 4))
    x = range(len(levels))
    ax.bar([i - 0.2 for i in x], fz, width=0.4, label="forward (z)")
    ax.bar([i + 0.2 for i in x], fy, width=0.4, label="upward (y)")
    ax.set_xticks(list(x))
    ax.set_xticklabels(levels, rotation=90)
    ax.set_ylabel("force on the back (N)")
    back = s["backrest_force_n"]
    ax.set_title(f"Back-chair contact ({chair_text(s)}): total "
                 f"{(back[1] ** 2 + back[2] ** 2) ** 0.5:.0f} N, seat {s['seat_force_n'][1]:.0f} N up")
    ax.legend()
    ax.grid(axis="y", alpha=0.3)
    return save(fig, d, "seating_contacts.png")


def l5s1(s, d):
    """Thesis fig. 6.8: L5-S1 force and moment in x, y, z, beside the load on every disc."""
    j = s["joints"][-1]
    f = [j["shear_lat_n"], j["axial_n"], j["shear_ap_n"]]
    m = [v / 1000 for v in j["moment_local_nmm"]]
    fig, axes = plt.subplots(1, 3, figsize=(12, 4), gridspec_kw={"width_ratios": [1, 1, 2.4]})
    axes[0].bar(["x", "y", "z"], f, color=["#888", "#c44", "#48c"])
    axes[0].set_title("L5-S1 force (N)")
    axes[1].bar(["x", "y", "z"], m, color=["#c84", "#888", "#888"])
    axes[1].set_title("L5-S1 moment (N·m)")
    names = [x["joint"] for x in s["joints"]]
    axes[2].plot(range(len(names)), [x["axial_n"] for x in s["joints"]], "o-", label="compression")
    axes[2].plot(range(len(names)), [x["shear_ap_n"] for x in s["joints"]], "s-", label="AP shear")
    axes[2].set_xticks(range(len(names)))
    axes[2].set_xticklabels(names, rotation=90)
    axes[2].set_ylabel("N")
    axes[2].set_title("Disc loads (joint frame)")
    axes[2].legend()
    for ax in axes:
        ax.grid(axis="y", alpha=0.3)
    return save(fig, d, "seating_l5s1.png")


def sweep(s, d):
    par = s["parameter"]
    x = s["values"]
    runs = s["runs"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    axes[0].plot(x, [r["joints"][-2]["axial_n"] for r in runs], "o-", label="L4-L5 compression")
    axes[0].plot(x, [r["joints"][-1]["axial_n"] for r in runs], "s-", label="L5-S1 compression")
    axes[0].set_xlabel(par)
    axes[0].set_ylabel("N")
    axes[0].legend()
    axes[0].set_title("Disc compression")
    back = [(r["backrest_force_n"][1] ** 2 + r["backrest_force_n"][2] ** 2) ** 0.5 for r in runs]
    axes[1].plot(x, [r["back_muscle_force_n"] for r in runs], "o-", label="back muscles (sum)")
    axes[1].plot(x, back, "s-", label="backrest force")
    axes[1].set_xlabel(par)
    axes[1].set_ylabel("N")
    axes[1].legend()
    axes[1].set_title("Back-muscle effort and backrest load")
    for ax in axes:
        ax.grid(alpha=0.3)
    return save(fig, d, "seating_sweep.png")


def findings_html(findings):
    if not findings:
        return ""
    rows = "".join(f"<tr><td>{'MATCH' if f['match'] else 'DIFFERS'}</td><td>{html.escape(f['thesis'])}"
                   f"</td><td>{html.escape(f['ours'])}</td></tr>" for f in findings)
    return ("<h2>Against the literature</h2><table><tr><th></th><th>literature</th><th>ours</th></tr>"
            f"{rows}</table>")


def read_and_draw(d, one, many):
    """The run's JSON and its figures: (title, figure names, extra HTML, provenance)."""
    if os.path.exists(many):
        with open(many) as f:
            s = json.load(f)
        title = f"Chair-design sweep over {s['parameter']}"
        figures = [sweep(s, d)]
        extra = findings_html(s["findings"])
    else:
        with open(one) as f:
            s = json.load(f)
        title = f"The spine in a chair: {chair_text(s)}"
        figures = [contacts(s, d), l5s1(s, d)]
        extra = ""
    return title, figures, extra, s.get("provenance")


def main(argv):
    d = folder_argument(argv, __doc__)
    one, many = os.path.join(d, "seating.json"), os.path.join(d, "seating_sweep.json")
    os.makedirs(os.path.join(d, "plots"), exist_ok=True)
    title, figures, extra, provenance = guarded(fail, d, lambda: read_and_draw(d, one, many))
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'>",
             f"<title>{html.escape(title)}</title><style>body{{font-family:sans-serif;"
             "max-width:1100px;margin:2em auto}img{max-width:100%}table{border-collapse:collapse}"
             "td,th{border:1px solid #ccc;padding:2px 6px}</style></head><body>",
             f"<h1>{html.escape(title)}</h1>"]
    parts += [f"<figure><img src='plots/{n}' alt='{n}'></figure>" for n in figures]
    parts.append(extra + "</body></html>")
    try:
        write_page(d, parts, provenance)
    except OSError as e:
        fail(f"cannot write in {d}: {e}")
    print(f"seating report: {os.path.join(d, 'report.html')} with {len(figures)} figures in "
          f"{os.path.join(d, 'plots')}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
