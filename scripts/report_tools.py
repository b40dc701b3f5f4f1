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
