#!/usr/bin/python3
"""Hostile mesh files for every reader knee_contact has written by hand.

The contact patch mesh of tests/meshes/patch_stack.geo (a mixed mesh) is
written in every format mesh_formats.py writes (.msh ASCII and binary, our
flat and multi-part and Gmsh's .inp, the 3D two-part deck of abaqus_3d.py,
.vtk in the ASCII and binary 4.2 layout and meshio's ASCII and binary 5.1
layout, .ucd, .vtu in five encodings); each file is then damaged with a fixed
seed: cut at several offsets, bytes overwritten by random bytes, a digit
changed into a large or negative number, lines dropped or repeated,
100 000 nested elements inserted, cut and extended by a hole to a sparse
file of 4.3 GB. Every
damaged file is run through the scene; as in fuzz.py, each run must end
within a time limit with exit code 0-3, never a crash, an internal error, a
sanitizer report or a hang, and a refusal (exit 1) must be one line
"knee_contact: error: ...". A damaged file may still be a valid mesh (a
changed coordinate): then the run ends with 0, 2 or 3 and that is fine.

Usage: reader_fuzz.py KNEE_CONTACT VARIANTS_PER_FILE
"""
import os
import random
import re
import subprocess
import sys
import tempfile

# Import the sibling scripts without leaving __pycache__ in the source tree.
sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "drivers"))
import abaqus_3d  # noqa: E402
import fuzz  # noqa: E402
import mesh_formats  # noqa: E402

SETS = {".inp": ("BODY_1: 1; BODY_2: 2",
                 "; ".join("SIDE_%d: %d" % (i, i) for i in range(1, 7))),
        "_gmsh.inp": ("PhysicalSurface1: 1; PhysicalSurface2: 2",
                      "; ".join("PhysicalLine%d: %d" % (i, i)
                                for i in range(1, 7))),
        "_parts.inp": ("", "LEFT: 1; RIGHT: 2; BOTTOM: 3; Upper-1.TOP: 4; "
                           "CONTACT_LOWER: 5; CONTACT_UPPER: 6")}


def damage(data, rng):
    """One damaged copy of data (bytes) and what was done; a copy to be
    made sparse is (bytes, size): a hole after the bytes up to 4.3 GB."""
    kind = rng.randrange(6)
    if kind == 4:
        # Elements (of XML; text in other formats) nested 100 000 deep.
        at = rng.randrange(len(data))
        return (data[:at] + b"<a>" * 100000 + b"</a>" * 100000 + data[at:],
                "100 000 nested elements at %d" % at)
    if kind == 5:
        # The file cut and continued by a hole of zeros to 4.3 GB.
        cut = rng.randrange(len(data))
        return (data[:cut], 4300000000), "cut at %d, sparse to 4.3 GB" % cut
    if kind == 0:
        cut = rng.randrange(len(data))
        return data[:cut], "cut at byte %d" % cut
    if kind == 1:
        at = rng.randrange(len(data))
        n = rng.randint(1, 8)
        noise = bytes(rng.randrange(256) for _ in range(n))
        return data[:at] + noise + data[at + n:], "%d random bytes at %d" % (
            n, at)
    if kind == 2:
        digits = [m.start() for m in re.finditer(rb"\d", data)]
        at = rng.choice(digits)
        value = rng.choice([b"99999999999", b"-1", b"4294967296", b"0"])
        return data[:at] + value + data[at + 1:], "digit at %d -> %s" % (
            at, value.decode())
    lines = data.split(b"\n")
    i = rng.randrange(len(lines))
    if rng.random() < 0.5:
        del lines[i]
        return b"\n".join(lines), "line %d dropped" % (i + 1)
    lines.insert(i, lines[i])
    return b"\n".join(lines), "line %d repeated" % (i + 1)


def main():
    program, per_file = os.path.abspath(sys.argv[1]), int(sys.argv[2])
    rng = random.Random(20261123)
    cases = []
    with tempfile.TemporaryDirectory() as folder:
        msh = os.path.join(folder, "mesh.msh")
        subprocess.run(["gmsh", "-2", "-format", "msh22", mesh_formats.GEO,
                        "-o", msh, "-setnumber", "mixed", "1"], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        gmsh_inp = os.path.join(folder, "mesh_gmsh.inp")
        subprocess.run(["gmsh", "-2", "-format", "inp", mesh_formats.GEO,
                        "-o", gmsh_inp, "-setnumber", "mixed", "1"],
                       check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        nodes, cells, lines = mesh_formats.read_msh22(msh)
        binary_msh = os.path.join(folder, "mesh_binary.msh")
        subprocess.run(["gmsh", "-2", "-format", "msh41", "-bin",
                        mesh_formats.GEO, "-o", binary_msh, "-setnumber",
                        "mixed", "1"], check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        files = {".msh": msh, "_binary.msh": binary_msh,
                 "_gmsh.inp": gmsh_inp}
        files["_parts.inp"] = os.path.join(folder, "mesh_parts.inp")
        mesh_formats.write_inp_parts(files["_parts.inp"], nodes, cells, lines,
                                     include=False)
        for suffix, write in ((".inp", mesh_formats.write_inp),
                              (".vtk", mesh_formats.write_vtk),
                              (".ucd", mesh_formats.write_ucd)):
            files[suffix] = os.path.join(folder, "mesh" + suffix)
            write(files[suffix], nodes, cells, lines)
        # Legacy VTK beside the ASCII 4.2 file: binary 4.2 (big-endian
        # values after the keyword lines) and meshio's 5.1 layout.
        files["_42_binary.vtk"] = os.path.join(folder, "mesh_42_binary.vtk")
        mesh_formats.write_vtk42_binary(files["_42_binary.vtk"], nodes, cells,
                                        lines, "double")
        import meshio
        for name, binary in (("ascii", False), ("binary", True)):
            suffix = "_meshio_%s.vtk" % name
            files[suffix] = os.path.join(folder, "mesh" + suffix)
            meshio.write(files[suffix], meshio.read(msh), binary=binary)
        for encoding in ("ascii", "binary", "binary1", "zlib", "appended"):
            suffix = "_%s.vtu" % encoding
            files[suffix] = os.path.join(folder, "mesh" + suffix)
            mesh_formats.write_vtu(files[suffix], nodes, cells, lines,
                                   encoding)
        # The 3D two-part deck (hexahedra and tetrahedra, which are split
        # into hexahedra; skew rotation, *Elastic) with its own scene.
        deck_3d = os.path.join(folder, "mesh_3d_parts.inp")
        abaqus_3d.write_deck(deck_3d, (False, True))
        scene_3d = abaqus_3d.two_instance_scene(
            "@WORK@/mesh.inp").replace("@FOLDER@", "@WORK@/out")
        for _ in range(per_file):
            damaged, what = damage(open(deck_3d, "rb").read(), rng)
            cases.append(("mesh_3d_parts.inp: %s" % what, scene_3d,
                          ("mesh.inp", damaged)))
        for suffix, path in sorted(files.items()):
            data = open(path, "rb").read()
            element_sets, boundary_sets = SETS.get(suffix, ("", ""))
            extension = suffix[suffix.rindex("."):]
            scene = mesh_formats.SCENE.format(
                file="@WORK@/mesh" + extension, folder="@WORK@/out",
                pictures="false", element_sets=element_sets,
                boundary_sets=boundary_sets, **mesh_formats.PHYSICAL_IDS)
            for _ in range(per_file):
                damaged, what = damage(data, rng)
                cases.append(("mesh%s: %s" % (suffix, what), scene,
                              ("mesh" + extension, damaged)))

    return fuzz.run_cases(program, cases, "damaged mesh files")

if __name__ == "__main__":
    sys.exit(main())
