#!/usr/bin/python3
"""The error bars of one mesh against true errors, for every quantity a run
reports beside the peak pressure and the energy (issue 24): each
interface's contact force (goal-oriented: the influence of all its active
pairs) and contact length (one slave spacing per contact edge), and each
material's tau_yy min and max and von Mises max (strain recovery).

Each scene runs on one mesh (Refinement/Number of cycles = 1, so no bar
comes from a mesh sequence) at Mesh/Global refinements 0 and 1, and its
summary.json's bars are compared with the distance to a reference computed
independently of the estimators: the same scene uniformly refined four
times (5 036 804 dofs for the Hertz scenes, three times and 200 006 dofs
for the knee), with the last change of that sequence as the reference's
uncertainty. These scenes were not used to choose the estimators (the
stress bar's cell-range term was chosen on the knee's stress extremes,
which are singular at corners and are not asserted here):
  - tests/accuracy/hertz_two_materials.prm (the two-material Hertz);
  - the same with the cylinder 2 000 times stiffer than the block;
  - tests/accuracy/knee.prm's mesh: its two forces (the insert-tray carries
    the load, 68 800 N/m, by equilibrium: its bar must be zero to
    round-off), contact lengths and the insert-tray's peak pressure (the
    condyle's is in accuracy/error_bars).
Asserted, over the (scene, quantity, mesh) pairs:
  (1) the true error lies within the bar up to the reference's uncertainty
      in at least 90 %;
  (2) the bar is at most 10 times the true error in at least 90 % of the
      pairs whose true error is above 3 times the reference's uncertainty
      (the length's bar is a bound, one spacing per edge: measured 1.2 to
      8 times);
  (3) every bar is finite; the insert-tray's force bar and error are below
      1e-8 of the force.
Halving the bars fails (1).
Usage: one_mesh_bars.py KNEE_CONTACT [SCENE_DIR]
"""
import os
import re
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from error_bars import ACCURACY, run, with_absolute_mesh  # noqa: E402

# Reference (value, uncertainty) per quantity, from the uniform sequences
# described above.
HERTZ = {
    "hertz force": (0.00250874841, 1e-10),
    "hertz contact length": (0.0999426078, 4.6e-05),
    "cylinder tau_yy min": (-0.0317524484, 2.9e-05),
    "cylinder tau_yy max": (0.000441774568, 0.00018),
    "block tau_yy min": (-0.0317549252, 1.4e-05),
    "block tau_yy max": (0.00076269224, 4.4e-06),
    "cylinder von Mises max": (0.0180835483, 8.2e-05),
    "block von Mises max": (0.0183095094, 7.4e-06),
}
STIFF = {
    "hertz force": (0.00250584732, 1e-10),
    "hertz contact length": (0.0817544381, 4.6e-05),
    "cylinder tau_yy min": (-0.0388000606, 3.2e-05),
    "cylinder tau_yy max": (0.000321480051, 0.00025),
    "block tau_yy min": (-0.0388059972, 2.3e-05),
    "block tau_yy max": (0.000906837801, 0.0007),
    "cylinder von Mises max": (0.0220799009, 1.1e-05),
    "block von Mises max": (0.0221550837, 1.1e-05),
}
KNEE = {
    "condyle force": (68916.4964, 0.3),
    "condyle contact length": (0.0105682751, 0.00011),
    "insert-tray force": (68800.0, 7e-4),
    "insert-tray contact length": (0.0174813916, 0.0003),
    # Its peak is sharp on coarse meshes (the peak bar's floor, the peak's
    # difference from its patch's mean, holds it): the uniform sequence of
    # prm/knee.prm's mesh to 4.6e5 dofs, 6.2685, 6.3111, 6.3262, 6.3299
    # MPa, extrapolates with order 1.9 to 6.3311 MPa; this mesh's sequence
    # approaches from above and is at 6.349 MPa at 2.0e5 dofs.
    "insert-tray peak pressure": (6.3311e6, 2e4),
}
SCENES = [
    ("Hertz, two materials", "hertz_two_materials.prm", HERTZ, {}),
    ("Hertz, stiff on soft", "hertz_two_materials.prm", STIFF,
     {"Materials/Material 0": {"Young's modulus": "1000"}}),
    ("knee", "knee.prm", KNEE, {}),
]


def refined_copy(scene, level, folder):
    """The scene with an absolute mesh path and Mesh/Global refinements =
    level, written into folder."""
    text = re.sub(r"^\s*set\s+Global refinements\s*=.*$", "",
                  with_absolute_mesh(scene),
                  flags=re.MULTILINE)
    text, n = re.subn(r"^subsection Mesh\n",
                      "subsection Mesh\n  set Global refinements = %d\n"
                      % level, text, count=1, flags=re.MULTILINE)
    assert n == 1, scene
    copy = os.path.join(folder, "%s_%d.prm" % (
        os.path.basename(scene)[:-4], level))
    with open(copy, "w") as f:
        f.write(text)
    return copy


def reported(summary):
    """The run's (value, bar) per quantity name of the tables above."""
    q = {}
    for name, i in summary["contact_interfaces"].items():
        q[name + " force"] = (i["force"], i["force_error"])
        q[name + " contact length"] = (i["contact_length"],
                                       i["contact_length_error"])
        q[name + " peak pressure"] = (i["max_pressure"],
                                      i["max_pressure_error"])
    for name, s in summary["stress_yy"].items():
        q[name + " tau_yy min"] = (s["min"], s["min_error"])
        q[name + " tau_yy max"] = (s["max"], s["max_error"])
    for name, s in summary["von_mises_max"].items():
        q[name + " von Mises max"] = (s["max"], s["max_error"])
    return q


def main():
    binary = os.path.abspath(sys.argv[1])
    scenes = sys.argv[2] if len(sys.argv) > 2 else ACCURACY
    failures = []
    inside = tight = judged = total = 0
    with tempfile.TemporaryDirectory() as folder:
        for label, scene, references, entries in SCENES:
            for level in (0, 1):
                copy = refined_copy(os.path.join(scenes, scene), level,
                                    folder)
                _, summary, _ = run(
                    binary, copy, folder,
                    {"Strategy": "global", "Number of cycles": 1},
                    "%s_%d" % (label.replace(" ", "_").replace(",", ""),
                               level), entries)
                values = reported(summary)
                for name, (reference, uncertainty) in references.items():
                    value, bar = values[name]
                    true = abs(value - reference)
                    total += 1
                    if bar is None or bar != bar or bar == float("inf"):
                        failures.append("%s, mesh %d: %s has no finite bar"
                                        % (label, level, name))
                        continue
                    ok = true <= bar + uncertainty
                    inside += ok
                    ratio = ""
                    if true > 3 * uncertainty:
                        judged += 1
                        tight += bar <= 10 * true
                        ratio = "%.2f" % (bar / true)
                    print("%-22s mesh %d %-26s %.6g +- %.2g, true %.2g "
                          "(reference +- %.2g) %s %s" % (
                              label, level, name, value, bar, true,
                              uncertainty, ratio,
                              "" if ok else "OUTSIDE"))
                    if name == "insert-tray force" and (
                            bar > 1e-8 * value or true > 1e-8 * value):
                        failures.append("knee mesh %d: the insert-tray's "
                                        "force %.10g +- %.2g (the load "
                                        "68 800)" % (level, value, bar))
    print("inside: %d of %d; at most 10 times the true error: %d of %d"
          % (inside, total, tight, judged))
    if inside < 0.9 * total:
        failures.append("fewer than 90 % of the true errors inside the bars")
    if tight < 0.9 * judged:
        failures.append("fewer than 90 % of the bars at most 10 times the "
                        "true error")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
