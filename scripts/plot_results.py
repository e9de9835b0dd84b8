#!/usr/bin/python3
"""Pictures of a knee_contact result folder (Debian's python3-matplotlib).

Reads cells.npy, summary.json and contact_*.csv written by knee_contact and
draws, each written to a temporary name and renamed:
  deformation.png       the deformed mesh (displacement magnified as the scene
                        asks, the seed's Fig. 2) over the undeformed outline,
                        bodies coloured by material, labelled points;
  stress_yy.png         the vertical stress tau_yy in MPa (the seed's Fig. 3);
  contact_pressure.png  the contact pressure in MPa along each interface.
Usage: plot_results.py FOLDER
"""
import csv
import glob
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402


def save(figure, path):
    temporary = path + ".part.png"
    figure.savefig(temporary, dpi=150, bbox_inches="tight")
    plt.close(figure)
    os.replace(temporary, path)


def read_cells(folder):
    data = np.load(os.path.join(folder, "cells.npy")).astype(float)
    material = data[:, 0].astype(int)
    vertex = data[:, 2:].reshape(len(data), 4, 5)
    return material, vertex  # vertex[cell, k] = x, y, u_x, u_y, stress_yy


def deformation(folder, summary, material, vertex):
    magnification = summary.get("deformation_magnification", 10)
    names = {v["material_id"]: name
             for name, v in summary.get("stress_yy", {}).items()}
    colours = plt.get_cmap("tab10")
    ids = sorted(set(material))
    figure, axes = plt.subplots(figsize=(8, 8))
    undeformed = vertex[:, :, 0:2]
    deformed = undeformed + magnification * vertex[:, :, 2:4]
    axes.add_collection(PolyCollection(undeformed, facecolors="none",
                                       edgecolors="0.75", linewidths=0.3))
    for i, m in enumerate(ids):
        cells = material == m
        axes.add_collection(PolyCollection(
            deformed[cells], facecolors=colours(i % 10), alpha=0.8,
            edgecolors="k", linewidths=0.1, label=names.get(m, str(m))))
    for name, (x, y) in summary.get("labels", {}).items():
        axes.plot(x, y, "ko", markersize=3)
        axes.annotate(name, (x, y), textcoords="offset points",
                      xytext=(4, 4), fontsize=9)
    axes.autoscale_view()
    axes.set_aspect("equal")
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    axes.set_title("deformation x %g (grey: undeformed)" % magnification)
    axes.legend(loc="best", fontsize=8)
    save(figure, os.path.join(folder, "deformation.png"))


def stress_yy(folder, material, vertex):
    # Each cell keeps its own vertex values (stress is discontinuous between
    # cells and materials): two triangles per cell, Gouraud shading.
    n = len(vertex)
    x = vertex[:, :, 0].ravel()
    y = vertex[:, :, 1].ravel()
    value = vertex[:, :, 4].ravel() / 1e6
    base = 4 * np.arange(n)[:, None]
    # A triangle (P1) repeats its third vertex: it has no second half.
    quadrilateral = ~np.all(vertex[:, 2, 0:2] == vertex[:, 3, 0:2], axis=1)
    triangles = np.vstack([base + [0, 1, 2],
                           (base + [0, 2, 3])[quadrilateral]])
    low, high = np.percentile(value, [0.5, 99.5])
    figure, axes = plt.subplots(figsize=(8, 8))
    image = axes.tripcolor(mtri.Triangulation(x, y, triangles), value,
                           shading="gouraud", cmap="jet", vmin=low,
                           vmax=high)
    bar = figure.colorbar(image, ax=axes, extend="both", shrink=0.8)
    bar.set_label("stress_yy [MPa] (0.5-99.5 percentile range; "
                  "min %.3g, max %.3g)" % (value.min(), value.max()))
    axes.set_aspect("equal")
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    axes.set_title("vertical stress tau_yy")
    save(figure, os.path.join(folder, "stress_yy.png"))


def contact_pressure(folder):
    files = sorted(glob.glob(os.path.join(folder, "contact_*.csv")))
    if not files:
        return
    figure, axes = plt.subplots(figsize=(8, 4.5))
    for path in files:
        with open(path) as f:
            rows = list(csv.DictReader(f))
        s = np.array([float(r["arc_length"]) for r in rows]) * 1e3
        p = np.array([float(r["pressure"]) for r in rows]) / 1e6
        name = os.path.basename(path)[len("contact_"):-len(".csv")]
        if rows and "discretisation" in rows[0]:
            name += " (%s)" % rows[0]["discretisation"]
        axes.plot(s, p, ".-", label=name)
    axes.set_xlabel("arc length along the slave side [mm]")
    axes.set_ylabel("contact pressure [MPa]")
    axes.grid(True, alpha=0.3)
    axes.legend(loc="best")
    save(figure, os.path.join(folder, "contact_pressure.png"))


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_results.py FOLDER")
    folder = sys.argv[1]
    with open(os.path.join(folder, "summary.json")) as f:
        summary = json.load(f)
    material, vertex = read_cells(folder)
    deformation(folder, summary, material, vertex)
    stress_yy(folder, material, vertex)
    contact_pressure(folder)


if __name__ == "__main__":
    main()
