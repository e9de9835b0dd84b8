#!/usr/bin/python3
"""The picture process of one knee_contact run.

knee_contact starts it once, at the start of a run, so that Python's and
matplotlib's start (about 0.6 s) overlaps the mesh and the solve instead of
adding to the user's wait; it then asks it for the pictures of each result
set it writes and waits for the answer. (Drawing a set's figures in forked
children was tried: on this project's 2-core machine each child drew 2.7
times slower, copying the parent's pages, and the set took longer.)

Protocol (no shell, no parsing of paths): each request on standard input is
two fields, each ended by a NUL byte: the drawing (plot_results,
plot_results_3d, plot_study, plot_load_cases: the scripts beside this one)
and the folder it draws from and into. Each answer is one line on file
descriptor 3: "ok", or "error: " and the first line of what went wrong.
Standard output and error go to the run's log. End of input ends it.
Usage: pictures.py (started by knee_contact)
"""
import io
import os
import select
import sys
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import plot_load_cases  # noqa: E402
import plot_results  # noqa: E402
import plot_results_3d  # noqa: E402
import plot_study  # noqa: E402

DRAWINGS = {
    "plot_results": plot_results,
    "plot_results_3d": plot_results_3d,
    "plot_study": plot_study,
    "plot_load_cases": plot_load_cases,
}


def one_line(error):
    lines = ("%s: %s" % (type(error).__name__, error)).splitlines()
    return lines[0] if lines else type(error).__name__


def warm_up():
    """Draw a small figure (fonts, the Agg renderer: 0.05 s of the first
    picture) while the program solves, unless a request is waiting."""
    if select.select([sys.stdin], [], [], 0)[0]:
        return
    figure, axes = plt.subplots(figsize=(2, 2))
    axes.plot([0, 1], [0, 1], ".-", label="warm-up")
    axes.legend()
    figure.savefig(io.BytesIO(), format="png", dpi=50, bbox_inches="tight")
    plt.close(figure)


def requests(stream):
    """Yield (drawing, folder) pairs read from NUL-ended fields."""
    buffer = b""
    fields = []
    while True:
        chunk = os.read(stream, 65536)
        if not chunk:
            return
        buffer += chunk
        while b"\0" in buffer:
            field, buffer = buffer.split(b"\0", 1)
            fields.append(os.fsdecode(field))
            if len(fields) == 2:
                yield fields[0], fields[1]
                fields = []


def main():
    answers = os.fdopen(3, "w", buffering=1)
    warm_up()
    for drawing, folder in requests(sys.stdin.fileno()):
        try:
            if drawing not in DRAWINGS:
                raise ValueError("no drawing called '%s'" % drawing)
            DRAWINGS[drawing].draw(folder)
            answers.write("ok\n")
        except Exception as error:  # each failure is answered, not fatal
            traceback.print_exc()
            sys.stderr.flush()
            answers.write("error: %s\n" % one_line(error))


if __name__ == "__main__":
    main()
