#!/usr/bin/python3
"""Picture of a 3D knee_contact result folder (Debian's python3-matplotlib).

Reads surface.npy and summary.json written by knee_contact for a 3D scene
and draws, written to a temporary name and renamed:
  von_mises.png  the deformed boundary surface (displacement magnified as the
                 scene asks) coloured by the von Mises stress in MPa, from two
                 views (front-left-above and back-right-below), with a
                 scale bar and the directions of x, y and z.
  pressure_<interface>.png  per contact interface, the contact pressure
                 in MPa on the slave surface seen along its mean normal (the
                 view a pressure-sensitive film gives), interpolated between
                 the slave vertices, the contact outline (where the active
                 flag changes) and the peak marked.
  friction_<interface>.png  per frictional interface, the same view with
                 each slave vertex's status (stick, slip, open) and the
                 slipping vertices' slip in the case (in the view's plane).
The views are orthographic and drawn back to front by each face's mean
depth, not per pixel: fine for the convex-ish bodies of a scene, not a
renderer (open solution.vtu in ParaView for that).
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
from matplotlib.collections import PolyCollection  # noqa: E402

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
    low, high = stress.min(), stress.max()
    if high - low <= 1e-6 * max(abs(high), 1e-300):
        # A uniform field (a patch test): the scale from 0 to its value,
        # not a range of round-off shown with an offset.
        low, high = min(0.0, low), max(high, 1e-300)
    norm = plt.Normalize(low, high)
    colours = plt.get_cmap("viridis")(norm(stress))
    figure, panes = plt.subplots(1, 2, figsize=(12, 6))
    for axes, (elevation, azimuth) in zip(panes, [(25, -60), (-25, 120)]):
        projected_view(axes, deformed, colours, elevation, azimuth)
    mappable = plt.cm.ScalarMappable(norm=norm, cmap="viridis")
    figure.colorbar(mappable, ax=figure.axes, shrink=0.6,
                    label="von Mises stress [MPa]")
    figure.suptitle("deformed surface (displacement x %g)" % magnification)
    save(figure, os.path.join(folder, "von_mises.png"))
    for name in summary.get("contact_interfaces", {}):
        pressure_map(folder, name)


def view_axes(elevation, azimuth):
    """The screen's right and up directions and the direction towards the
    viewer, for a view from @p elevation above the x-y plane and at
    @p azimuth about z (degrees, as matplotlib's view_init)."""
    e, a = np.radians(elevation), np.radians(azimuth)
    towards = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a),
                        np.sin(e)])
    right = np.array([-np.sin(a), np.cos(a), 0.0])
    return right, np.cross(towards, right), towards


def projected_view(axes, faces, colours, elevation, azimuth):
    """The faces (n x 4 x 3, in m) in an orthographic view, drawn
    back to front by their mean depth (a painter's order, as mplot3d's,
    not per pixel), with a scale bar and the axes' directions. Drawn as one
    2D collection: mplot3d's Poly3DCollection projects and sorts face by
    face in Python (8.8 s for the 2.5e4 faces of the 3D knee at 2.3e5 dofs,
    25 s at 1e6: the run waits for it)."""
    right, up, towards = view_axes(elevation, azimuth)
    screen = np.stack([faces @ right, faces @ up], axis=-1) * 1e3  # mm
    order = np.argsort((faces @ towards).mean(axis=1))
    # Edges only where the faces are large enough to show them.
    edges = dict(edgecolors="k", linewidths=0.05) if len(faces) < 2e4 \
        else dict(edgecolors="face", linewidths=0.1)
    axes.add_collection(PolyCollection(screen[order],
                                       facecolors=colours[order], **edges))
    points = screen.reshape(-1, 2)
    low, high = points.min(0), points.max(0)
    margin = 0.05 * (high - low).max()
    axes.set_xlim(low[0] - margin, high[0] + margin)
    axes.set_ylim(low[1] - 3 * margin, high[1] + margin)
    axes.set_aspect("equal")
    axes.set_axis_off()
    # A scale bar of a round length about a fifth of the width.
    width = high[0] - low[0]
    bar = 10 ** np.floor(np.log10(max(width / 5, 1e-12)))
    bar *= 5 if 5 * bar <= width / 2 else 2 if 2 * bar <= width / 2 else 1
    y = low[1] - 1.5 * margin
    axes.plot([low[0], low[0] + bar], [y, y], "k-", lw=2)
    axes.annotate("%g mm" % bar, (low[0] + 0.5 * bar, y), ha="center",
                  va="top", textcoords="offset points", xytext=(0, -3))
    # The x, y and z directions as seen, at the lower right.
    origin = np.array([high[0] - margin, low[1] - 1.5 * margin])
    for k, name in enumerate("xyz"):
        direction = np.array([right[k], up[k]]) * 1.5 * margin
        axes.annotate("", origin + direction, origin,
                      arrowprops=dict(arrowstyle="->", lw=1))
        axes.annotate(name, origin + 1.3 * direction, ha="center",
                      va="center", fontsize=8)
    axes.set_title("seen from elevation %g, azimuth %g degrees"
                   % (elevation, azimuth), fontsize=9)


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
