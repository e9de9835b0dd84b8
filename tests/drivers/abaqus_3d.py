#!/usr/bin/python3
"""3D Abaqus decks: gmsh's own .inp export and a hand-written multi-part deck.

1. gmsh's .inp of tests/meshes/block.geo (two bonded materials; hexahedra
   C3D8 and tetrahedra C3D4, boundary faces as CPS4/CPS3 elements in
   PhysicalSurface element sets), run as tests/scenes/bonded_blocks_3d.prm
   runs the .geo: the analytic checks pass (nodal displacements and stresses
   to 1e-10 relative) and every number of summary.json equals the .msh run's
   to 1e-12 relative to the largest of its kind.
2. A deck written here from the Abaqus keywords' documented layout: one
   *Part BLOCK (a 1 x 1 x 2 box of 2 x 2 x 4 hexahedra, or of the same
   hexahedra split into six tetrahedra each; a third deck has one part of
   each kind, which knee_contact solves with its tetrahedra split into
   hexahedra), two *Instance of it in an
   *Assembly: B1 where the part is, B2 translated by (3, 0, 0) and rotated
   by 40 degrees about the axis from (4, 1, 1) to (5, 3, 4); surfaces of
   element faces (S1-S6, tetrahedra S1-S4) and node sets of the part,
   named INSTANCE.SET in the scene; *Material/*Elastic per instance through
   two *Solid Sections, taken with Materials/Elastic constants = mesh file
   (the scene gives one modulus again, equal, and leaves the others to
   the deck; the defaults it would otherwise use differ). Each block is
   in uniaxial compression q on its top with its bottom and two sides
   sliding (the rotated block on rotated planes, its traction rotated):
   u = R u_local(R^T (X - c) + c) with u_local = (nu q/E (x - x0),
   nu q/E y, -q/E z) and stress -q n n^T, n = R e_z; linear, so Q1 and P1
   reproduce it. Asserted: the analytic checks to 1e-10 relative.
Reference: the analytic solutions and the .msh run.
Usage: abaqus_3d.py KNEE_CONTACT
"""
import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from mesh_formats import numbers  # noqa: E402

BLOCK_GEO = os.path.join(HERE, "..", "meshes", "block.geo")
BONDED = os.path.join(HERE, "..", "scenes", "bonded_blocks_3d.prm")
TOLERANCE = 1e-12


def run(binary, scene_text, folder, name):
    out = os.path.join(folder, name)
    scene = os.path.join(folder, name + ".prm")
    with open(scene, "w") as f:
        f.write(scene_text.replace("@FOLDER@", out))
    result = subprocess.run([binary, scene], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    print(result.stdout[-1500:])
    if result.returncode != 0:
        raise SystemExit("%s: exit code %d" % (name, result.returncode))
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def bonded_scene(mesh, sets):
    """bonded_blocks_3d.prm with another mesh and files written."""
    text = open(BONDED).read()
    mesh_section = ("subsection Mesh\n  set Source = file\n  set File = %s\n"
                    "%s"
                    "end\n" % (mesh, sets))
    start = text.index("subsection Mesh")
    end = text.index("end\n", start) + 4
    text = text[:start] + mesh_section + text[end:]
    return text.replace(
        "  set Terminal    = test\n  set Write files = false\n",
        "  set Folder = @FOLDER@\n  set Pictures = false\n")


def compare(name, reference, other):
    a, b = dict(numbers(reference)), dict(numbers(other))
    assert a.keys() == b.keys(), (name, a.keys() ^ b.keys())
    worst, failures = 0.0, 0
    for key in a:
        top = key.split("/")[1]
        if top == "equilibrium_residual":
            scale = 1.0  # round-off measure: compared absolutely
        elif top in ("stress_yy", "von_mises_max"):
            # tau_yy is 0 in these scenes (its extremes are round-off):
            # relative to the largest stress.
            scale = max(abs(v) for k, v in a.items()
                        if k.split("/")[1] in ("stress_yy", "von_mises_max"))
        else:
            scale = max(abs(v) for k, v in a.items()
                        if k.split("/")[1] == top) or 1.0
        error = abs(a[key] - b[key]) / scale
        worst = max(worst, error)
        if error > TOLERANCE:
            print("FAIL %s: %s = %r, .msh gives %r" % (name, key, b[key],
                                                     a[key]))
            failures += 1
    print("%s: %d numbers, largest relative difference to .msh %.1e "
          "(tolerance %.0e)" % (name, len(a), worst, TOLERANCE))
    return failures


# ---------------------------------------------------------------------------
# The hand-written two-instance deck.

N = (2, 2, 4)  # hexahedra along x, y, z of the 1 x 1 x 2 part
MATERIALS = {"B1": ("BONE", 7e8, 0.35), "B2": ("TI6AL4V", 2e9, 0.25)}
Q = 1e6
TRANSLATION = (3.0, 0.0, 0.0)
AXIS = ((4.0, 1.0, 1.0), (5.0, 3.0, 4.0))
ANGLE = 40.0
# Abaqus' faces of C3D8 and C3D4 (node positions, 0-based).
HEX_FACES = [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2),
             (2, 6, 7, 3), (3, 7, 4, 0)]
TET_FACES = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]


def part_mesh(tets):
    nodes = {}
    for k in range(N[2] + 1):
        for j in range(N[1] + 1):
            for i in range(N[0] + 1):
                nodes[1 + i + (N[0] + 1) * (j + (N[1] + 1) * k)] = (
                    i / N[0], j / N[1], 2.0 * k / N[2])

    def node(i, j, k):
        return 1 + i + (N[0] + 1) * (j + (N[1] + 1) * k)

    elements = []
    for k in range(N[2]):
        for j in range(N[1]):
            for i in range(N[0]):
                # Bottom face round it, then the top face.
                hexa = [node(i, j, k), node(i + 1, j, k),
                        node(i + 1, j + 1, k), node(i, j + 1, k),
                        node(i, j, k + 1), node(i + 1, j, k + 1),
                        node(i + 1, j + 1, k + 1), node(i, j + 1, k + 1)]
                if not tets:
                    elements.append(hexa)
                    continue
                # Six tetrahedra round the diagonal from corner (0,0,0) to
                # (1,1,1): conforming between neighbours; some are listed
                # inside out, as meshers do.
                corner = {(a, b, c): node(i + a, j + b, k + c)
                          for a in (0, 1) for b in (0, 1) for c in (0, 1)}
                for axes in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0),
                             (2, 0, 1), (2, 1, 0)):
                    p = [0, 0, 0]
                    tet = [corner[tuple(p)]]
                    for axis in axes[:2]:
                        p[axis] = 1
                        tet.append(corner[tuple(p)])
                    tet.append(corner[(1, 1, 1)])
                    elements.append(tet)
    return nodes, elements


def faces_on(nodes, elements, plane):
    """(element number, face number) of the faces on a plane."""
    table = HEX_FACES if len(elements[0]) == 8 else TET_FACES
    result = []
    for e, element in enumerate(elements):
        for f, face in enumerate(table):
            if all(plane(nodes[element[n]]) for n in face):
                result.append((e + 1, f + 1))
    return result


def write_deck(path, tets):
    """tets: per instance (B1, B2), whether its part is of tetrahedra."""
    with open(path, "w") as f:
        f.write("*Heading\n** two parts and their instances, written by "
                "abaqus_3d.py\n")
        for (instance, (material, E, nu)), part_tets in zip(
                MATERIALS.items(), tets):
            write_part(f, "Part" + instance, material, part_tets)
        f.write("**\n*Assembly, name=Assembly\n")
        f.write("*Instance, name=B1, part=PartB1\n*End Instance\n")
        f.write("*Instance, name=B2, part=PartB2\n%g, %g, %g\n"
                % TRANSLATION)
        f.write("%g, %g, %g, %g, %g, %g, %g\n*End Instance\n"
                % (AXIS[0] + AXIS[1] + (ANGLE,)))
        f.write("*End Assembly\n**\n")
        for material, E, nu in MATERIALS.values():
            f.write("*Material, name=%s\n*Density\n4430.,\n*Elastic\n"
                    "%.17g, %.17g\n" % (material, E, nu))
        f.write("*Step, name=Load\n*Static\n*End Step\n")


def write_part(f, part, material, tets):
    nodes, elements = part_mesh(tets)
    kind = "C3D4" if tets else "C3D8R"
    f.write("*Part, name=%s\n*Node\n" % part)
    for n, p in nodes.items():
        f.write("%d, %.17g, %.17g, %.17g\n" % ((n,) + p))
    f.write("*Element, type=%s\n" % kind)
    for e, element in enumerate(elements):
        # Continued over two lines, as CAE writes long elements.
        numbers_ = [str(e + 1)] + [str(n) for n in element]
        if len(numbers_) > 5:
            f.write(", ".join(numbers_[:5]) + ",\n" +
                    ", ".join(numbers_[5:]) + "\n")
        else:
            f.write(", ".join(numbers_) + "\n")
    f.write("*Elset, elset=ALL, generate\n1, %d, 1\n" % len(elements))
    # Bottom and top as surfaces of element faces; the sides as node
    # sets.
    for name, plane in (("BOTTOM", lambda p: p[2] == 0.0),
                        ("TOP", lambda p: p[2] == 2.0)):
        faces = faces_on(nodes, elements, plane)
        for face in sorted({f for _, f in faces}):
            f.write("*Elset, elset=_%s_S%d, internal\n" % (name, face))
            members = [str(e) for e, k in faces if k == face]
            for i in range(0, len(members), 16):
                f.write(", ".join(members[i:i + 16]) + "\n")
        f.write("*Surface, type=ELEMENT, name=%s\n" % name)
        for face in sorted({f for _, f in faces}):
            f.write("_%s_S%d, S%d\n" % (name, face, face))
    for name, axis in (("XSIDE", 0), ("YSIDE", 1)):
        f.write("*Nset, nset=%s\n" % name)
        members = [str(n) for n, p in nodes.items() if p[axis] == 0.0]
        for i in range(0, len(members), 16):
            f.write(", ".join(members[i:i + 16]) + "\n")
    f.write("*Solid Section, elset=ALL, material=%s\n,\n*End Part\n"
            % material)


def rotation():
    a, b = AXIS
    k = [b[i] - a[i] for i in range(3)]
    norm = math.sqrt(sum(x * x for x in k))
    k = [x / norm for x in k]
    t = math.radians(ANGLE)
    c, s = math.cos(t), math.sin(t)
    K = [[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]]
    return [[c * (i == j) + s * K[i][j] + (1 - c) * k[i] * k[j]
             for j in range(3)] for i in range(3)]


def two_instance_scene(deck):
    R = rotation()
    c = AXIS[0]
    # Block 2's exact solution as A X + b.
    m2, E2, nu2 = MATERIALS["B2"]
    m1, E1, nu1 = MATERIALS["B1"]
    D = [nu2 * Q / E2, nu2 * Q / E2, -Q / E2]
    shift = [-TRANSLATION[0], -TRANSLATION[1], -TRANSLATION[2]]
    # X_local = c + R^T (X - c); u_local = D * (X_local + shift);
    # u = R u_local.
    RT = [[R[j][i] for j in range(3)] for i in range(3)]
    M = [[R[i][k] * D[k] for k in range(3)] for i in range(3)]  # R D
    A = [[sum(M[i][k] * RT[k][j] for k in range(3)) for j in range(3)]
         for i in range(3)]
    x_local_0 = [c[i] - sum(RT[i][j] * c[j] for j in range(3)) + shift[i]
                 for i in range(3)]
    b = [sum(M[i][k] * x_local_0[k] for k in range(3)) for i in range(3)]
    u1 = ["%.17g*x" % (nu1 * Q / E1), "%.17g*y" % (nu1 * Q / E1),
          "%.17g*z" % (-Q / E1)]
    u2 = ["%.17g*x + %.17g*y + %.17g*z + %.17g"
          % (A[i][0], A[i][1], A[i][2], b[i]) for i in range(3)]
    exact_u = "; ".join("if(x > 1.6, %s, %s)" % (u2[i], u1[i])
                        for i in range(3))
    n = [R[i][2] for i in range(3)]
    sigma2 = [-Q * n[i] * n[j] for i, j in ((0, 0), (1, 1), (2, 2), (0, 1),
                                             (0, 2), (1, 2))]
    sigma1 = [0, 0, -Q, 0, 0, 0]
    exact_s = "; ".join("if(x > 1.6, %.17g, %.17g)" % (s2, s1)
                        for s2, s1 in zip(sigma2, sigma1))
    traction = "; ".join("%.17g" % (-Q * x) for x in n)
    return """
subsection Mesh
  set Source = file
  set File   = {deck}
  set Abaqus element sets  = B1.ALL: 1; B2.ALL: 2
  set Abaqus boundary sets = B1.BOTTOM: 1; B1.XSIDE: 2; B1.YSIDE: 3; \\
    B1.TOP: 4; B2.BOTTOM: 11; B2.XSIDE: 12; B2.YSIDE: 13; B2.TOP: 14
end
subsection Materials
  set Elastic constants   = mesh file
  set Number of materials = 2
  subsection Material 0
    set Material id     = 1
    set Name            = bone
  end
  subsection Material 1
    set Material id     = 2
    set Name            = tray
    set Young's modulus = {E2}
  end
end
subsection Boundary conditions
  set Number of conditions = 3
  subsection Condition 0
    set Boundary ids = 1, 2, 3, 11, 12, 13
    set Type         = sliding
  end
  subsection Condition 1
    set Boundary ids = 4
    set Type         = traction
    set Value        = 0; 0; {minus_q}
  end
  subsection Condition 2
    set Boundary ids = 14
    set Type         = traction
    set Value        = {traction}
  end
end
subsection Contact
  set Number of interfaces = 0
end
subsection Output
  set Folder   = @FOLDER@
  set Pictures = false
end
subsection Verification
  set Exact displacement = {exact_u}
  set Exact stress       = {exact_s}
  set Tolerance          = 1e-10
end
""".format(deck=deck, E2="%.17g" % E2, minus_q="%.17g" % -Q,
           traction=traction, exact_u=exact_u, exact_s=exact_s)


def main():
    binary = os.path.abspath(sys.argv[1])
    failures = 0
    with tempfile.TemporaryDirectory() as folder:
        for kind, hexes in (("hexahedra", "1"), ("tetrahedra", "0")):
            arguments = ["-setnumber", "hex", hexes, "-setnumber", "n", "2",
                         "-setnumber", "two", "1"]
            msh = os.path.join(folder, kind + ".msh")
            inp = os.path.join(folder, kind + ".inp")
            for path, form in ((msh, "msh22"), (inp, "inp")):
                subprocess.run(["gmsh", "-3", BLOCK_GEO, "-format", form,
                                "-o", path] + arguments, check=True,
                               stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
            reference = run(binary, bonded_scene(msh, ""), folder,
                            kind + "_msh")
            sets = ("  set Abaqus element sets = PhysicalVolume1: 1; "
                    "PhysicalVolume2: 2\n  set Abaqus boundary sets = " +
                    "; ".join("PhysicalSurface%d: %d" % (i, i)
                              for i in range(1, 7)) + "\n")
            other = run(binary, bonded_scene(inp, sets), folder,
                        kind + "_gmsh_inp")
            failures += compare("gmsh .inp, " + kind, reference, other)
        # The third deck has both kinds (hexahedra below, tetrahedra
        # above): knee_contact splits its tetrahedra into hexahedra.
        for name, tets in (("parts_hexahedra", (False, False)),
                           ("parts_tetrahedra", (True, True)),
                           ("parts_hexahedra_and_tetrahedra", (False, True))):
            deck = os.path.join(folder, name + ".inp")
            write_deck(deck, tets)
            run(binary, two_instance_scene(deck), folder, name)
            print("%s: analytic checks passed" % name)
    if failures:
        raise SystemExit("%d differences" % failures)


if __name__ == "__main__":
    main()
