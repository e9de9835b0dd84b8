#!/usr/bin/python3
"""The sparse path's factor, CHOLMOD against MUMPS, on 1 and 2 ranks: a table.

Usage: direct_factor.py KNEE_CONTACT SCENE.prm [--ranks 1 2] [--repeat 3]
           [--change PATTERN REPLACEMENT]...

Runs the scene with Contact/Solver = sparse and Contact/Direct factor =
CHOLMOD and MUMPS on each rank count (N = 1 as one process, N > 1 under
mpirun; CHOLMOD then factorises the whole matrix on every rank, MUMPS
divides the factor over them). --change makes a regular-expression
substitution in the scene first (e.g. its first load case only, a finer
mesh). Read from each run's summary.json: the factorisations (count and
time), the contact solve, the factor's memory on rank 0 (CHOLMOD's
factor; MUMPS's INFO(22), its workspace included) against the estimate
the path choice made of it (9.6 bytes per entry of CHOLMOD's analysis,
divided by N for MUMPS) and MUMPS's own (INFO(15)), the peak resident
memory of rank 0, and the largest relative difference of the contact
forces and peak pressures from the first run. Times are medians over
--repeat runs, ratios of medians measured in this one invocation (the
machine is noisy). doc/parallel.md has the measured table.
"""
import argparse
import os
import re
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from parallel_scaling import contact_numbers, run, scene_text  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary")
    parser.add_argument("scene")
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--change", nargs=2, action="append", default=[],
                        metavar=("PATTERN", "REPLACEMENT"))
    args = parser.parse_args()
    binary = os.path.abspath(args.binary)
    text = scene_text(args.scene, "sparse")
    for pattern, replacement in args.change:
        text, n = re.subn(pattern, replacement, text)
        if n == 0:
            sys.exit("--change: %r is not in the scene" % pattern)
    stem = os.path.splitext(os.path.basename(args.scene))[0]

    rows, reference = [], None
    for ranks in args.ranks:
        for factor in ("CHOLMOD", "MUMPS"):
            scene = text.replace("subsection Contact", "subsection Contact\n"
                                 "  set Direct factor = %s" % factor, 1)
            runs = [run(binary, scene, os.path.abspath(os.path.join(
                "output", "direct_factor",
                "%s_%s_%d_%d" % (stem, factor, ranks, k))), ranks)
                for k in range(args.repeat)]
            summaries = [summary for summary, _ in runs]

            def median(key):
                return statistics.median(s["solver"].get(key, 0)
                                         for s in summaries)

            numbers = contact_numbers(summaries[0])
            if reference is None:
                reference = numbers
            difference = max([abs(numbers[k] - reference[k]) /
                              abs(reference[k])
                              for k in reference if reference[k]] + [0.0])
            estimate = 9.6 * median("factor_entries") / 1048576. / (
                ranks if factor == "MUMPS" else 1)
            rows.append((ranks, factor, summaries[0]["n_dofs"],
                         median("factorisations"), median("factorisation"),
                         median("contact_solve"), median("factor_memory_MB"),
                         estimate,
                         median("mumps_estimated_MB"),
                         median("peak_memory_MB"), difference))

    print("| ranks | factor | DoFs | factorisations | factorisations [s] "
          "| contact solve [s] | speed-up (solve) | factor, rank 0 [MB] "
          "| estimate: path choice / MUMPS's [MB] | peak, rank 0 [MB] "
          "| forces, peaks vs first |")
    print("|" + "---|" * 11)
    base = rows[0][5]
    for (ranks, factor, dofs, count, factorise, solve, memory, estimate,
         own, peak, difference) in rows:
        print("| %d | %s | %d | %d | %.1f | %.1f | %.2f | %.0f | %.0f / %s "
              "| %.0f | %.1e |" % (
                  ranks, factor, dofs, count, factorise, solve,
                  base / max(solve, 1e-9), memory, estimate,
                  "%.0f" % own if own else "-", peak, difference))


if __name__ == "__main__":
    main()
