#!/usr/bin/python3
"""Speed-against-error pictures of a knee_contact study (Refinement/Strategy
= compare), from FOLDER/study.csv:
  study_error_dofs.png   each error the scene has a reference for against
                         n_dofs, uniform and adaptive on the same axes;
  study_error_time.png   the same against the wall time of the cycle;
  study_cost.txt         per strategy, the dofs and wall time of the first
                         cycle whose peak pressure (else energy) error is
                         below 5 %, 1 % and 0.1 %.
Usage: plot_study.py FOLDER
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ERRORS = ["peak_pressure_error", "pressure_L2_error", "contact_length_error",
          "energy_error", "L2_error", "energy_vs_reference",
          "extreme_stress_yy_error"]


def save(figure, path):
    temporary = path + ".part.png"
    figure.savefig(temporary, dpi=150, bbox_inches="tight")
    plt.close(figure)
    os.replace(temporary, path)


def draw(folder):
    with open(os.path.join(folder, "study.csv")) as f:
        rows = list(csv.DictReader(f))
    strategies = []
    for r in rows:
        if r["strategy"] not in strategies:
            strategies.append(r["strategy"])
    present = [e for e in ERRORS
               if all(not math.isnan(float(r[e])) for r in rows)]
    for x_key, x_label, name in (("dofs", "degrees of freedom",
                                  "study_error_dofs.png"),
                                 ("time_total", "wall time per cycle [s]",
                                  "study_error_time.png")):
        figure, axes = plt.subplots(figsize=(7, 5))
        for e, colour in zip(present, plt.get_cmap("tab10").colors):
            for s, style in zip(strategies, ("o-", "s--")):
                points = [(float(r[x_key]), float(r[e])) for r in rows
                          if r["strategy"] == s and float(r[e]) > 0]
                if points:
                    axes.loglog(*zip(*points), style, color=colour,
                                label="%s, %s" % (e.replace("_", " "), s))
        axes.set_xlabel(x_label)
        axes.set_ylabel("relative error (contact length: [m])")
        axes.grid(True, which="both", alpha=0.3)
        axes.legend(fontsize=7)
        save(figure, os.path.join(folder, name))

    primary = "peak_pressure_error" if "peak_pressure_error" in present \
        else "energy_error"
    lines = ["error measure: %s" % primary,
             "strategy, target, dofs, wall time [s] (first cycle below)"]
    for s in strategies:
        for target in (0.05, 0.01, 0.001):
            hit = [r for r in rows if r["strategy"] == s and
                   float(r[primary]) <= target]
            lines.append("%s, %g, %s" % (
                s, target, "%s, %.3g" % (hit[0]["dofs"],
                                         float(hit[0]["time_total"]))
                if hit else "not reached, -"))
    with open(os.path.join(folder, "study_cost.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_study.py FOLDER")
    draw(sys.argv[1])


if __name__ == "__main__":
    main()
