#!/usr/bin/python3
"""Bodies moved rigidly along a frictional load path (Load cases/Motion,
issue 37): a block dragged over a base by its pose, in 2D and 3D.

The block and base of scenes/friction_sliding_block(_3d).prm (block
E = 3e9, nu = 0.2 on a base E = 1e9, nu = 0.3, mortar, mu = 0.3,
non-matching meshes; tetrahedra in 3D), the block's top held at its pose
and pressed down by 1e-4 m, the base's bottom held. Each load case places
the block by a Load cases/Motion: t = 0 where it is meshed, t = 1 dragged
by D = 0.3 m along e (0.3 rad off x in 3D, x in 2D), t = 2 held there,
t = 3 pulled back by 0.1 m, and in 3D t = 4 twisted by 10 degrees about
the block's centre. The pairs are found anew in each case, and each
pair's slip counts the rigid sliding of the block over the base since the
previous case. Statics and kinematics give, independently of the mesh and
the moduli (asserted per case, from the contact CSVs):
- dragged (t = 1) and pulled back (t = 3): every pair in contact slips, the
  friction force is mu N (N the normal force) to 1e-8 relative (measured
  3e-10) and opposes the motion: the force on the block is -e at t = 1,
  +e at t = 3, to 1e-4 rad (measured 0 in 2D, 1.2e-5 in 3D, where the
  elastic slips turn single pairs by up to max|u| / D = 3e-4); each
  vertex's slip is the rigid sliding within 5 max|u| (the elastic
  displacements; measured 2);
- held (t = 2): nothing moves, every pair sticks and the friction force is
  t = 1's to 1e-8 (a pair at its bound stays there; the loop's stick test
  allows half its tolerance of round-off there);
- twisted (3D, t = 4): every pair slips along the chord of its rigid
  rotation, so the moment of the friction about the axis is
  -mu cos(5 deg) sum(p w r) (p w a vertex's normal force, r its distance
  from the axis) to 1e-5 (measured 7e-7; the infinitesimal rotation's
  tangent would give -mu sum(p w r), 3.8e-3 off); each slip is the chord
  2 sin(5 deg) r within 5 max|u| (measured 1.3); the accumulated slip
  D + 0.1 + chord within 8 max|u| (four cases' elastic parts; measured
  3.7).
Usage: motion.py KNEE_CONTACT
"""
import csv
import json
import math
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from friction import run_scene  # noqa: E402

SCENES = os.path.normpath(os.path.join(HERE, "..", "scenes"))
MU, D, BACK, TWIST = 0.3, 0.3, 0.1, 10.0


def scene(dim, folder):
    """The sliding block scene of @p dim with the block's top held and the
    drag as a motion."""
    name = "friction_sliding_block" + ("_3d" if dim == 3 else "")
    with open(os.path.join(SCENES, name + ".prm")) as f:
        text = f.read()
    text = text[text.index("subsection Mesh"):text.index("subsection Output")]
    text = text.replace("../meshes/", os.path.join(SCENES, "..", "meshes/"))
    zero = "; ".join(["0"] * dim)
    press = "0; 0; -1e-4" if dim == 3 else "0; -1e-4"
    for old in ("    set Type         = pressure\n    set Value        = 1e6\n",):
        assert old in text
        text = text.replace(old, "    set Type         = displacement\n"
                            "    set Value        = %s\n" % press)
    start = text.index("  subsection Condition 2")
    end = text.index("  end\n", start) + len("  end\n")
    text = (text[:start] + "  subsection Condition 2\n"
            "    set Boundary ids = 5\n    set Type         = traction\n"
            "    set Value        = %s\n  end\n" % zero + text[end:])
    path = "if(t < 0.5, 0, if(t < 2.5, %g, %g))" % (D, D - BACK)
    if dim == 3:
        translation = "%s * cos(0.3); %s * sin(0.3); 0" % (path, path)
        values, angle = "0, 1, 2, 3, 4", "if(t > 3.5, %g, 0)" % TWIST
    else:
        translation, values, angle = path + "; 0", "0, 1, 2, 3", "0"
    text += """subsection Load cases
  set Values of t       = %s
  set Number of motions = 1
  subsection Motion 0
    set Material ids    = 2
    set Rotation angle  = %s
    set Translation     = %s
  end
end
subsection Output
  set Folder   = %s
  set Pictures = false
end
""" % (values, angle, translation, folder)
    return text


def read(folder, case):
    base = os.path.join(folder, "case_%03d" % case)
    with open(os.path.join(base, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(base, "contact_block.csv")) as f:
        rows = [r for r in csv.DictReader(f) if r["active"] == "1"]
    return summary, rows


def vectors(rows, dim):
    """Per pair in contact: position, normal force p w, tangential traction
    times weight and slip as Cartesian vectors (the CSV's traction is
    along the slip: the force on the slave is its negative)."""
    out = []
    for r in rows:
        w = float(r["weight"])
        x = [float(r[k]) for k in "xyz"[:dim]]
        if dim == 3:
            t = [float(r["tangential_traction_" + k]) * w for k in "xyz"]
            s = [float(r["slip_" + k]) for k in "xyz"]
        else:
            tangent = [float(r["t_x"]), float(r["t_y"])]
            t = [float(r["tangential_traction"]) * w * c for c in tangent]
            s = [float(r["slip"]) * c for c in tangent]
        out.append((x, float(r["pressure"]) * w, t, s, r["status"],
                    float(r["accumulated_slip"])))
    return out


failures = []


def check(what, value, limit):
    ok = value <= limit
    print("%-70s %.3e <= %.1e: %s" % (what, value, limit,
                                      "PASS" if ok else "FAIL"))
    if not ok:
        failures.append(what)


def norm(v):
    return math.sqrt(sum(c * c for c in v))


def run(binary, dim, folder):
    out = os.path.join(folder, "drag%d" % dim)
    run_scene(binary, scene(dim, out), folder, "drag%d" % dim)
    e = [math.cos(0.3), math.sin(0.3), 0.0] if dim == 3 else [1.0, 0.0]
    cases = 5 if dim == 3 else 4
    forces = {}
    for case in range(cases):
        summary, rows = read(out, case)
        check("%dD case %d: converged" % (dim, case),
              0 if summary["converged"] else 1, 0)
        pairs = vectors(rows, dim)
        u_max = summary["max_displacement"]
        normal = sum(p for _, p, _, _, _, _ in pairs)
        force = [-sum(t[i] for _, _, t, _, _, _ in pairs) for i in range(dim)]
        forces[case] = force
        statuses = set(status for _, _, _, _, status, _ in pairs)
        if case in (1, 3):
            sign = -1 if case == 1 else 1
            check("%dD case %d: every pair in contact slips" % (dim, case),
                  0 if statuses == {"slip"} else 1, 0)
            check("%dD case %d: |friction force| / (mu N) - 1" % (dim, case),
                  abs(norm(force) / (MU * normal) - 1), 1e-8)
            cosine = sign * sum(f * c for f, c in zip(force, e)) / norm(force)
            check("%dD case %d: angle of the force on the block from %se"
                  " [rad]" % (dim, case, "-" if sign < 0 else "+"),
                  math.acos(min(1.0, cosine)), 1e-4)
            rigid = D if case == 1 else BACK
            check("%dD case %d: slip - rigid sliding, over max|u|"
                  % (dim, case),
                  max(norm([s[i] + sign * rigid * e[i] for i in range(dim)])
                      for _, _, _, s, _, _ in pairs) / u_max, 5)
        if case == 2:
            check("%dD case 2 (held): every pair sticks" % dim,
                  0 if statuses == {"stick"} else 1, 0)
            check("%dD case 2 (held): friction force - case 1's, relative"
                  % dim,
                  norm([a - b for a, b in zip(force, forces[1])]) /
                  norm(forces[1]), 1e-8)
        if case == 4:
            centre = [(D - BACK) * c for c in e]
            half = math.radians(TWIST / 2)
            moment = reference = 0.0
            slip_error = accumulated_error = 0.0
            for x, p, t, s, _, accumulated in pairs:
                r = [x[0] - centre[0], x[1] - centre[1]]
                radius = norm(r)
                # The force on the block is -t.
                moment += -(r[0] * t[1] - r[1] * t[0])
                reference += -MU * math.cos(half) * p * radius
                chord = 2 * math.sin(half) * radius
                # The chord from where the point was to where it is.
                before = [math.cos(-2 * half) * r[0] - math.sin(-2 * half) *
                          r[1], math.sin(-2 * half) * r[0] +
                          math.cos(-2 * half) * r[1]]
                rigid = [r[0] - before[0], r[1] - before[1], 0.0]
                slip_error = max(slip_error, norm([a - b for a, b in
                                                   zip(s, rigid)]))
                accumulated_error = max(
                    accumulated_error, abs(accumulated - (D + BACK + chord)))
            check("3D case 4 (twisted): every pair in contact slips",
                  0 if statuses == {"slip"} else 1, 0)
            check("3D case 4: friction moment / (-mu cos(5 deg) sum p w r) - 1",
                  abs(moment / reference - 1), 1e-5)
            check("3D case 4: 1e-3 / |moment / (-mu sum p w r) - 1| (the"
                  " chord, not the tangent)",
                  1e-3 / abs(moment * math.cos(half) / reference - 1), 1)
            check("3D case 4: slip - rigid chord, over max|u|",
                  slip_error / u_max, 5)
            check("3D case 4: accumulated slip - (D + 0.1 + chord), over"
                  " max|u|", accumulated_error / u_max, 8)


def main():
    binary = sys.argv[1]
    with tempfile.TemporaryDirectory() as folder:
        for dim in (2, 3):
            run(binary, dim, folder)
    if failures:
        raise SystemExit("failed: " + "; ".join(failures))


if __name__ == "__main__":
    main()
