#!/usr/bin/python3
"""Pictures of a knee_contact result folder (Debian's python3-matplotlib).

Reads cells.npy, summary.json and contact_*.csv written by knee_contact and
draws, each written to a temporary name and renamed:
  deformation.png       the deformed mesh (displacement magnified as the scene
                        asks, the seed's Fig. 2) over the undeformed outline,
                        bodies coloured by material, labelled points;
  stress_yy.png         the vertical stress tau_yy in MPa (the seed's Fig. 3);
  contact_pressure.png  the contact pressure in MPa along each interface,
                        and the peak pressure's error bar as a band where
                        the run has one;
  contact_friction.png  with friction: along each frictional interface the
                        normal and tangential traction in MPa (and the
                        bound mu p where it is Coulomb), the slip of this
                        load case and the accumulated slip in micrometres,
                        sticking vertices marked.
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


def contact_pressure(folder, summary):
    files = sorted(glob.glob(os.path.join(folder, "contact_*.csv")))
    if not files:
        return
    figure, axes = plt.subplots(figsize=(8, 4.5))
    interfaces = summary.get("contact_interfaces", {})
    for path in files:
        with open(path) as f:
            rows = list(csv.DictReader(f))
        s = np.array([float(r["arc_length"]) for r in rows]) * 1e3
        p = np.array([float(r["pressure"]) for r in rows]) / 1e6
        interface = os.path.basename(path)[len("contact_"):-len(".csv")]
        name = interface
        if rows and "discretisation" in rows[0]:
            name += " (%s)" % rows[0]["discretisation"]
        line, = axes.plot(s, p, ".-", label=name)
        # The peak pressure's error bar as a band at the peak.
        entry = interfaces.get(interface, {})
        error = entry.get("max_pressure_error")
        if error is not None and len(p) and np.isfinite(error):
            peak = entry["max_pressure"] / 1e6
            axes.axhspan(peak - error / 1e6, peak + error / 1e6,
                         color=line.get_color(), alpha=0.2,
                         label="%s: peak %.4g +- %.2g MPa" %
                         (interface, peak, error / 1e6))
    axes.set_xlabel("arc length along the slave side [mm]")
    axes.set_ylabel("contact pressure [MPa]")
    axes.grid(True, alpha=0.3)
    axes.legend(loc="best")
    save(figure, os.path.join(folder, "contact_pressure.png"))


def contact_friction(folder):
    """Tractions and slip along each interface that has friction columns."""
    tables = []
    for path in sorted(glob.glob(os.path.join(folder, "contact_*.csv"))):
        with open(path) as f:
            rows = list(csv.DictReader(f))
        if rows and "tangential_traction" in rows[0]:
            tables.append((os.path.basename(path)[len("contact_"):-4], rows))
    if not tables:
        return
    figure, axes = plt.subplots(2, len(tables), figsize=(8 * len(tables), 7),
                                squeeze=False, sharex="col")
    for column, (name, rows) in enumerate(tables):
        s = np.array([float(r["arc_length"]) for r in rows]) * 1e3
        p = np.array([float(r["pressure"]) for r in rows]) / 1e6
        q = np.array([float(r["tangential_traction"]) for r in rows]) / 1e6
        slip = np.array([float(r["slip"]) for r in rows]) * 1e6
        total = np.array([float(r["accumulated_slip"]) for r in rows]) * 1e6
        stick = np.array([r["status"] == "stick" for r in rows])
        top, bottom = axes[0][column], axes[1][column]
        top.plot(s, p, ".-", label="normal traction (pressure)")
        top.plot(s, q, ".-", label="tangential traction")
        top.plot(s[stick], q[stick], "o", mfc="none", color="k",
                 label="sticking")
        top.set_ylabel("traction [MPa]")
        top.set_title(name)
        bottom.plot(s, slip, ".-", label="slip of this load case")
        bottom.plot(s, total, ".-", label="accumulated slip")
        bottom.set_ylabel("slip [um]")
        bottom.set_xlabel("arc length along the slave side [mm]")
        # Where the sides touch, with a margin of a fifth on either side.
        touching = s[np.array([r["status"] != "open" for r in rows])]
        if touching.size and touching.max() > touching.min():
            margin = 0.2 * (touching.max() - touching.min())
            top.set_xlim(touching.min() - margin, touching.max() + margin)
        for a in (top, bottom):
            a.grid(True, alpha=0.3)
            a.legend(loc="best")
    save(figure, os.path.join(folder, "contact_friction.png"))


def draw(folder):
    with open(os.path.join(folder, "summary.json")) as f:
        summary = json.load(f)
    material, vertex = read_cells(folder)
    deformation(folder, summary, material, vertex)
    stress_yy(folder, material, vertex)
    contact_pressure(folder, summary)
    contact_friction(folder)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_results.py FOLDER")
    draw(sys.argv[1])


if __name__ == "__main__":
    main()
