"""What the report scripts share (report.py, seating_report.py, disc_report.py): the one-line
failure with its exit status, and matplotlib without a display."""
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
