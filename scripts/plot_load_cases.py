#!/usr/bin/python3
"""Picture of a knee_contact load-case run (Load cases/Values of t), from
FOLDER/load_cases.csv:
  load_cases.png   against the load parameter t: peak contact pressure and
                   contact length of every interface, the applied load and
                   the reaction of every Gamma_u/Gamma_o boundary id; with
                   friction also each interface's sticking length and its
                   largest slip in the case and accumulated along the path
                   (micromotion).
Usage: plot_load_cases.py FOLDER
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def draw(folder):
    with open(os.path.join(folder, "load_cases.csv")) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError("load_cases.csv has no cases")
    columns = list(rows[0].keys())
    t = [float(r["t"]) for r in rows]
    interfaces = [c[: -len("_peak_pressure")] for c in columns
                  if c.endswith("_peak_pressure")]
    reactions = sorted({c[len("reaction_"):].rsplit("_", 1)[0]
                        for c in columns if c.startswith("reaction_")},
                       key=lambda s: int(s))

    friction = [n for n in interfaces if n + "_max_slip" in columns]
    # 3D: contact areas [m^2] (shown in mm^2), forces in N, the load along z.
    three_d = "load_z" in columns
    measure, scale = (("_contact_area", 1e6) if three_d
                      else ("_contact_length", 1e3))
    figure, axes = plt.subplots(4 if friction else 3, 1,
                                figsize=(7, 12 if friction else 9),
                                sharex=True)
    for name in interfaces:
        axes[0].plot(t, [float(r[name + "_peak_pressure"]) / 1e6
                         for r in rows], "o-", ms=3, label=name)
        line, = axes[1].plot(t, [float(r[name + measure]) * scale
                                 for r in rows], "o-", ms=3, label=name)
        if name in friction:
            stick = "_stick_area" if three_d else "_stick_length"
            axes[1].plot(t, [float(r[name + stick]) * scale
                             for r in rows], "--", color=line.get_color(),
                         label=name + ": sticking")
    for name in friction:
        line, = axes[3].plot(t, [float(r[name + "_max_slip"]) * 1e6
                                 for r in rows], "o-", ms=3,
                             label=name + ": largest slip in the case")
        axes[3].plot(t, [float(r[name + "_max_accumulated_slip"]) * 1e6
                         for r in rows], "--", color=line.get_color(),
                     label=name + ": largest accumulated slip")
    if friction:
        axes[3].set_ylabel("slip [um]")
    axes[0].set_ylabel("peak contact pressure [MPa]")
    axes[1].set_ylabel("contact area [mm^2]" if three_d
                       else "contact length [mm]")
    components = (("z", "-"), ("x", "--"), ("y", ":")) if three_d \
        else (("y", "-"), ("x", "--"))
    for component, style in components:
        axes[2].plot(t, [float(r["load_" + component]) / 1e3 for r in rows],
                     "k" + style, label="applied load " + component)
        for b in reactions:
            axes[2].plot(t, [float(r["reaction_%s_%s" % (b, component)]) / 1e3
                             for r in rows], style, marker="o", ms=3,
                         label="reaction id %s %s" % (b, component))
    axes[2].set_ylabel("force [kN]" if three_d else "force [kN/m]")
    axes[-1].set_xlabel("load parameter t")
    for a in axes:
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7)
    not_converged = [float(r["t"]) for r in rows if r["converged"] != "true"]
    if not_converged:
        axes[0].set_title("NOT converged at t = %s" % not_converged)
    path = os.path.join(folder, "load_cases.png")
    temporary = path + ".part.png"
    figure.savefig(temporary, dpi=150, bbox_inches="tight")
    plt.close(figure)
    os.replace(temporary, path)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_load_cases.py FOLDER")
    draw(sys.argv[1])


if __name__ == "__main__":
    main()
