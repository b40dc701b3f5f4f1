"""What the report scripts share (report.py, seating_report.py, disc_report.py,
identify_report.py): the one-line failure with its exit status, matplotlib without a display, the
page's head and the main of a one-folder report."""
import html
import json
import os
import sys


def failer(name):
    """A fail(message, status=1) for the script `name`. Exit 2 for a missing tool (the program
    warns and goes on), 1 for anything else (a read or a write that failed, e.g. a full disk: the
    program fails, the figures it promised are not all there)."""

    def fail(message, status=1):
        print(f"{name}: {message}; report.html not written", file=sys.stderr)
        sys.exit(status)

    return fail


def pyplot(fail):
    """matplotlib.pyplot on the Agg backend, or fail(…, 2) when python3-matplotlib is missing."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        fail("python3-matplotlib is missing (apt-get install python3-matplotlib)", 2)
    return plt


def guarded(fail, d, work):
    """work(), with a read or write that failed (a full disk) or bad input in the folder d turned
    into one line through fail."""
    try:
        return work()
    except OSError as e:
        fail(f"cannot read or write in {d}: {e}")
    except (ValueError, KeyError, TypeError, IndexError, ZeroDivisionError) as e:
        fail(f"bad input in {d}: {type(e).__name__} {e}")


def folder_argument(argv, doc):
    """The one argument DIR; --help (or no argument) prints the script's doc and exits."""
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(doc.strip())
        sys.exit(0 if len(argv) == 2 else 2)
    return argv[1]


def page_head(title, width=1400):
    """The report page's opening: doctype, title, the plain table and figure style, <h1>."""
    t = html.escape(title)
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{t}</title><style>"
            f"body{{font-family:sans-serif;max-width:{width}px;margin:2em auto}}"
            "img{max-width:100%}table{border-collapse:collapse}"
            f"td,th{{border:1px solid #ccc;padding:2px 6px}}</style></head><body><h1>{t}</h1>")


def report_main(argv, doc, fail, write_report):
    """The report scripts' main: the folder argument, write_report(d) → figure names, guarded,
    and the one line that says what was written."""
    d = folder_argument(argv, doc)
    figures = guarded(fail, d, lambda: write_report(d))
    print(f"report: {os.path.join(d, 'report.html')} with {len(figures)} figure(s) in "
          f"{os.path.join(d, 'plots')}")
    return 0


def secant_wedge(ax, top, low, high, label, alpha=0.25):
    """The in-vitro window low–high (stiffness, load per motion) as the wedge between
    load = k·motion for k in [low, high], from the origin up to the load `top`."""
    ax.fill([0, top / high, top / low], [0, top, top], color="C1", alpha=alpha, label=label)


def provenance_html(provenance):
    """The page's footer from a summary's "provenance" (program, commit, command, folder and the
    inputs' SHA-256), or "" without one."""
    if not provenance:
        return ""
    p = provenance
    rows = "".join(f"<tr><td><code>{html.escape(i['path'])}</code></td><td>{i['bytes']}</td>"
                   f"<td><code>{html.escape(str(i['sha256']))}</code></td></tr>"
                   for i in p.get("inputs", []))
    table = (f"<table><tr><th>input</th><th>bytes</th><th>SHA-256</th></tr>{rows}</table>"
             if rows else "")
    return (f"<footer><h2>Provenance</h2><p>Made by {html.escape(p['program'])} "
            f"{html.escape(p['version'])} (commit <code>{html.escape(p['commit'])}</code>) with "
            f"<pre>{html.escape(p['command'])}</pre> in <code>"
            f"{html.escape(p['working_directory'])}</code>.</p>{table}</footer>")


def write_page(d, parts, provenance=None):
    """DIR/report.html from the page's parts (page_head first, the closing tags last), with the
    provenance footer of the summary it reports (its "provenance" object) before the close."""
    footer = provenance_html(provenance)
    if footer and parts and parts[-1].endswith("</body></html>"):
        parts = parts[:-1] + [parts[-1][:-len("</body></html>")] + footer + "</body></html>"]
    with open(os.path.join(d, "report.html"), "w") as f:
        f.write("\n".join(parts))


def load_summary(d, name):
    """DIR/name read as JSON, and DIR/plots made for the figures."""
    with open(os.path.join(d, name)) as f:
        s = json.load(f)
    os.makedirs(os.path.join(d, "plots"), exist_ok=True)
    return s
