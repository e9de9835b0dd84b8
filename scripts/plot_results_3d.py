#!/usr/bin/python3
"""Picture of a 3D knee_contact result folder (Debian's python3-matplotlib).

Reads surface.npy and summary.json written by knee_contact for a 3D scene
and draws, written to a temporary name and renamed:
  von_mises.png  the deformed boundary surface (displacement magnified as the
                 scene asks) coloured by the von Mises stress in MPa, from two
                 views (front-left-above and back-right-below), with the
                 undeformed outline's bounding box for scale.
  pressure_<interface>.png  per contact interface, the contact pressure
                 in MPa on the slave surface seen along its mean normal (the
                 view a pressure-sensitive film gives), interpolated between
                 the slave vertices, the contact outline (where the active
                 flag changes) and the peak marked.
  friction_<interface>.png  per frictional interface, the same view with
                 each slave vertex's status (stick, slip, open) and the
                 slipping vertices' slip in the case (in the view's plane).
matplotlib's mplot3d sorts faces by depth, not per pixel: fine for the
convex-ish bodies of a scene, not a renderer (open solution.vtu in ParaView
for that). Measured: 0.9 s for 2.3e4 faces.
Usage: plot_results_3d.py FOLDER
"""
import csv
import json
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402
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
    for name in summary.get("contact_interfaces", {}):
        pressure_map(folder, name)


def csv_name(interface):
    """knee_contact's contact_<name>.csv (csv_file_name in contact.cc)."""
    return "contact_" + re.sub(r"[^A-Za-z0-9-]", "_", interface) + ".csv"


def pressure_map(folder, interface):
    path = os.path.join(folder, csv_name(interface))
    if not os.path.exists(path):
        return
    with open(path) as f:
        rows = list(csv.DictReader(f))
    if len(rows) < 3:
        return
    x = np.array([[float(r[k]) for k in ("x", "y", "z")] for r in rows])
    n = np.array([[float(r[k]) for k in ("n_x", "n_y", "n_z")] for r in rows])
    p = np.array([float(r["pressure"]) for r in rows]) / 1e6
    active = np.array([float(r["active"]) for r in rows])
    # The view: along the mean slave normal of the contact zone (of the
    # whole side if nothing is in contact), in-plane axes e1, e2.
    weights = active if active.any() else np.ones(len(rows))
    normal = (weights[:, None] * n).sum(0)
    normal /= np.linalg.norm(normal)
    helper = np.eye(3)[np.argmin(np.abs(normal))]
    e1 = np.cross(normal, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    centre = x.mean(0)
    s, t = (x - centre) @ e1, (x - centre) @ e2
    try:
        triangles = mtri.Triangulation(s * 1e3, t * 1e3)
    except (ValueError, RuntimeError):
        return  # all slave vertices on a line: nothing to map
    figure, axes = plt.subplots(figsize=(7, 6))
    top = max(p.max(), 1e-300)
    levels = np.linspace(0, top, 21)
    filled = axes.tricontourf(triangles, np.clip(p, 0, None), levels=levels,
                              cmap="inferno")
    if active.any() and not active.all():
        axes.tricontour(triangles, active, levels=[0.5], colors="cyan",
                        linewidths=1)
    axes.plot(s * 1e3, t * 1e3, ",", color="0.6")
    peak = int(np.argmax(p))
    axes.plot(s[peak] * 1e3, t[peak] * 1e3, "x", color="cyan", ms=10, mew=2)
    axes.annotate("peak %.4g MPa" % p[peak],
                  (s[peak] * 1e3, t[peak] * 1e3), textcoords="offset points",
                  xytext=(8, -14), color="cyan")
    # The contact zone and a margin of half its size (the whole side if
    # nothing is in contact).
    zone = active > 0.5 if active.any() else np.ones(len(rows), bool)
    zoom(axes, s, t, zone)
    axes.set_xlabel("e1 [mm]")
    axes.set_ylabel("e2 [mm]")
    figure.colorbar(filled, ax=axes, label="contact pressure [MPa]")
    axes.set_title("contact '%s': pressure seen along the mean slave normal\n"
                   "(%.2f, %.2f, %.2f); cyan: the contact outline and the peak"
                   % (interface, *normal), fontsize=10)
    save(figure, os.path.join(folder, "pressure_" +
                              csv_name(interface)[len("contact_"):-4] +
                              ".png"))
    if "status" in rows[0]:
        friction_map(folder, interface, rows, s, t, e1, e2, normal, zone)


def zoom(axes, s, t, zone):
    """The vertices of @p zone and a margin of half its size, in mm, at
    equal scales."""
    for values, limits in ((s, axes.set_xlim), (t, axes.set_ylim)):
        low, high = values[zone].min(), values[zone].max()
        margin = 0.5 * max(high - low, 1e-9 * max(np.ptp(s), np.ptp(t), 1))
        limits((low - margin) * 1e3, (high + margin) * 1e3)
    axes.set_aspect("equal")


def friction_map(folder, interface, rows, s, t, e1, e2, normal, zone):
    """The same view of a frictional interface: on the left each slave
    vertex coloured by its status (stick, slip, open) and the slipping
    ones' slip in this case drawn in the plane of the view (its part along
    the normal is not seen); on the right the accumulated slip along the
    load path (the micromotion) at each vertex."""
    status = np.array([r["status"] for r in rows])
    slip = np.array([[float(r[k]) for k in ("slip_x", "slip_y", "slip_z")]
                     for r in rows])
    accumulated = np.array([float(r["accumulated_slip"]) for r in rows])
    figure, (axes, right) = plt.subplots(1, 2, figsize=(13, 6))
    for kind, colour, size in (("open", "0.75", 4), ("stick", "tab:blue", 14),
                               ("slip", "tab:orange", 14)):
        chosen = status == kind
        axes.scatter(s[chosen] * 1e3, t[chosen] * 1e3, s=size, c=colour,
                     label="%s (%d)" % (kind, chosen.sum()))
    slipping = status == "slip"
    if slipping.any():
        u, v = slip[slipping] @ e1, slip[slipping] @ e2
        axes.quiver(s[slipping] * 1e3, t[slipping] * 1e3, u, v,
                    color="tab:red", angles="xy", width=0.004,
                    label="slip (largest %.3g m)"
                    % np.linalg.norm(slip[slipping], axis=1).max())
    zoom(axes, s, t, zone)
    axes.set_xlabel("e1 [mm]")
    axes.set_ylabel("e2 [mm]")
    axes.legend(loc="upper right", fontsize=8)
    axes.set_title("contact '%s': stick and slip seen along the mean slave "
                   "normal\n(%.2f, %.2f, %.2f)" % (interface, *normal),
                   fontsize=10)
    shown = right.scatter(s * 1e3, t * 1e3, s=14, c=accumulated * 1e6,
                          cmap="viridis")
    figure.colorbar(shown, ax=right, label="accumulated slip [µm]")
    zoom(right, s, t, zone)
    right.set_xlabel("e1 [mm]")
    right.set_ylabel("e2 [mm]")
    right.set_title("accumulated slip along the load path (micromotion),\n"
                    "largest %.3g µm" % (accumulated.max() * 1e6),
                    fontsize=10)
    save(figure, os.path.join(folder, "friction_" +
                              csv_name(interface)[len("contact_"):-4] +
                              ".png"))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_results_3d.py FOLDER")
    draw(sys.argv[1])
