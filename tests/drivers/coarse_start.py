#!/usr/bin/python3
"""Contact/Coarse start levels against the run without it.

The coarse start solves the contact problem on a coarser mesh first and
starts the run's loop from that contact zone; it must change how many
iterations the loop takes, never where it ends. Scenes:
- tests/scenes/hertz_sphere_3d_small.prm (3D, a .geo of tetrahedra: gmsh
  meshes it at twice the size; the sphere held only by contact, whose loop
  releases a ring of pairs per iteration from its usual start),
- tests/scenes/hertz_small.prm (2D, a .geo of triangles),
- tests/scenes/contact_separation.prm with Mesh/Global refinements = 2
  (Rectangles: the coarse mesh is one refinement fewer).
Reference: the same scene without the coarse start. Asserted: the same
exit code and active pairs (contact_*.csv), every figure of summary.json
(energy, max |u|, reactions, load, interface forces, peak pressures, tau_yy
ranges) equal to 1e-9 relative to its scale (the iterative and direct
paths stop at 1e-12 and 1e-10), and fewer active-set iterations on the
run's mesh on the 2D Hertz scene, no more on the 3D one (since the cold
start's first step from a body held at a point is damped, 2026-11-28, it
takes 4 iterations there too, 7 to 13 before). A scene that cannot be made
coarser (a .msh-less Rectangles scene without refinements) is refused in
one line naming the parameter.
Usage: coarse_start.py KNEE_CONTACT
"""
import json
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from load_cases import figures  # noqa: E402

SCENES = os.path.join(HERE, "..", "scenes")
TOLERANCE = 1e-9


def scene(folder, name, base, levels, extra=""):
    text = open(os.path.join(SCENES, base)).read()
    # Paths relative to the scene's folder, as ctest runs it.
    text = re.sub(r"(set File *= *)(\.\./\S+)",
                  lambda m: m.group(1) + os.path.normpath(
                      os.path.join(SCENES, m.group(2))), text)
    text = re.sub(r"set Terminal *= *test", "set Terminal = normal", text)
    text = re.sub(r"set Write files *= *false", "set Write files = true",
                  text)
    text += ("subsection Contact\n  set Coarse start levels = %d\nend\n"
             "subsection Output\n  set Folder = %s\n  set Pictures = false\n"
             "end\n%s" % (levels, os.path.join(folder, name), extra))
    path = os.path.join(folder, name + ".prm")
    with open(path, "w") as f:
        f.write(text)
    return path


def run(binary, path):
    result = subprocess.run([binary, path], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    return result.returncode, result.stdout


def fine_iterations(log):
    """Active-set iterations on the run's own mesh (after its cycle line)."""
    after = log[log.index("cycle 0:"):]
    return len(re.findall(r"active set iteration", after))


def main():
    binary = os.path.abspath(sys.argv[1])
    failures = 0
    cases = [("hertz_3d", "hertz_sphere_3d_small.prm", "", "no more"),
             ("hertz_2d", "hertz_small.prm", "", "fewer"),
             ("separation", "contact_separation.prm",
              "subsection Mesh\n  set Global refinements = 2\nend\n", "")]
    with tempfile.TemporaryDirectory() as folder:
        for name, base, extra, fewer in cases:
            runs = {}
            for levels in (0, 1):
                key = "%s_%d" % (name, levels)
                code, log = run(binary,
                                scene(folder, key, base, levels, extra))
                runs[levels] = (code, log, figures(os.path.join(folder, key)))
            (code0, log0, (fig0, act0)), (code1, log1, (fig1, act1)) = \
                runs[0], runs[1]
            if "coarse start level -1:" not in log1:
                print("%s: no coarse start in the log" % name)
                failures += 1
            if code0 != code1 or act0 != act1:
                print("%s: exit %d/%d, active pairs %s" %
                      (name, code0, code1,
                       "equal" if act0 == act1 else "differ"))
                failures += 1
            worst = 0
            for kind, values in fig0.items():
                scale = max([abs(v) for v in values] + [1e-300])
                for a, b in zip(values, fig1[kind]):
                    worst = max(worst, abs(a - b) / scale)
            it0, it1 = fine_iterations(log0), fine_iterations(log1)
            print("%s: largest difference %.2e (tolerance %.0e), active-set "
                  "iterations on the run's mesh %d without, %d with the "
                  "coarse start" % (name, worst, TOLERANCE, it0, it1))
            if worst > TOLERANCE:
                failures += 1
            if fewer == "fewer" and not it1 < it0:
                print("%s: the coarse start saved no iteration" % name)
                failures += 1
            if fewer == "no more" and not it1 <= it0:
                print("%s: the coarse start cost iterations" % name)
                failures += 1
        # A mesh that cannot be made coarser: refused in one line.
        code, log = run(binary, scene(folder, "refused",
                                      "contact_separation.prm", 1))
        lines = [l for l in log.splitlines() if "error" in l]
        if code == 0 or len(lines) != 1 or \
                "Contact/Coarse start levels" not in lines[0]:
            print("refusal: exit %d, %s" % (code, lines))
            failures += 1
        else:
            print("refusal: " + lines[0])
    if failures:
        raise SystemExit("%d failures" % failures)


if __name__ == "__main__":
    main()
