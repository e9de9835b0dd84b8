#!/usr/bin/python3
"""One contact patch test read from every mesh format knee_contact reads.

tests/meshes/patch_stack.geo is meshed by gmsh (triangles; with
-setnumber mixed 1 the upper block mostly quadrilaterals: a mixed mesh) and
the .msh is written out again, by this script, as an Abaqus input deck
(element sets per body, *Nset for the outer sides, element-face *Surface
for the contact sides, named in the scene; also with the node and element
data in files of their own, read through *Include and INPUT=; and gmsh writes its own .inp
with line elements for the sides), as a legacy VTK file and as
VTK XML .vtu files in the four encodings VTK and ParaView write (ascii,
base64, base64 of zlib blocks, raw appended; MaterialID of cells and of
boundary lines), and as an AVS UCD file; and as other programs write it:
meshio 5 (legacy VTK 5.1 ASCII and binary, .vtu with zlib; ids in
gmsh:physical), VTK 9 (5.1 ASCII with METADATA blocks, 5.1 and 4.2 binary)
and gmsh's VTK export (ASCII and binary, CellEntityIds), plus a 4.2 binary
file written here from the format's description (double and float points,
a POINT_DATA vector to skip); gmsh's binary .msh 4.1; and the .msh (2.2
and 4.1) of the same
mesh with its contact sides and both blocks also in a physical group the
scene does not name. The scene is the contact patch
test of tests/scenes/contact_patch_matching.prm (stiff block pressed on a soft one,
sides sliding, node pairs on the matching interface).

Asserted, per mesh (triangles, mixed):
- each run passes its analytic checks (displacement, stress and contact
  pressure to 1e-10 relative; exit code 0);
- every format gives the same results: every number of summary.json
  (energy, max |u|, reactions, forces, peak pressures, tau_yy ranges, ...)
  equal to 1e-12 relative to the largest of its kind, and the same
  contact pairs and pressures (contact_blocks.csv, sorted by position).
Reference: the analytic solution, and the .msh run for the other formats.
Usage: mesh_formats.py KNEE_CONTACT
"""
import base64
import csv
import json
import os
import struct
import subprocess
import sys
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
GEO = os.path.join(HERE, "..", "meshes", "patch_stack.geo")
TOLERANCE = 1e-12

SCENE = """
subsection Mesh
  set Source = file
  set File   = {file}
  set Abaqus element sets  = {element_sets}
  set Abaqus boundary sets = {boundary_sets}
end
subsection Materials
  set Number of materials = 2
  subsection Material 0
    set Material id     = 1
    set Name            = soft
    set Young's modulus = 1e9
    set Poisson's ratio = 0.3
  end
  subsection Material 1
    set Material id     = 2
    set Name            = stiff
    set Young's modulus = 3e9
    set Poisson's ratio = 0.2
  end
end
subsection Boundary conditions
  set Number of conditions = 3
  subsection Condition 0
    set Boundary ids = {bottom}
    set Type         = displacement
  end
  subsection Condition 1
    set Boundary ids = {sides}
    set Type         = sliding
  end
  subsection Condition 2
    set Boundary ids = {top}
    set Type         = pressure
    set Value        = 1e6
  end
end
subsection Contact
  set Number of interfaces = 1
  subsection Interface 0
    set Name               = blocks
    set Slave boundary id  = {slave}
    set Master boundary id = {master}
    set Pairing            = node-to-node
  end
end
subsection Output
  set Folder   = {folder}
  set Pictures = {pictures}
end
subsection Verification
  set Exact displacement     = 0; if(y < 1, -1e6*(1+0.3)*(1-2*0.3)/(1e9*(1-0.3))*y, \\
    -1e6*(1+0.3)*(1-2*0.3)/(1e9*(1-0.3))*1 - 1e6*(1+0.2)*(1-2*0.2)/(3e9*(1-0.2))*(y - 1))
  set Exact stress           = if(y < 1, -1e6*0.3/0.7, -1e6*0.2/0.8); -1e6; 0
  set Exact contact pressure = 1e6
  set Tolerance              = 1e-10
end
"""


def read_msh22(path):
    """Nodes {tag: (x, y)}, cells [(physical, [tags])], lines [(physical,
    [tags])] of a Gmsh 2.2 ASCII file."""
    nodes, cells, lines = {}, [], []
    with open(path) as f:
        text = f.read().split("\n")
    i = text.index("$Nodes")
    for row in text[i + 2:i + 2 + int(text[i + 1])]:
        tag, x, y, _ = row.split()
        nodes[int(tag)] = (float(x), float(y))
    i = text.index("$Elements")
    for row in text[i + 2:i + 2 + int(text[i + 1])]:
        v = [int(w) for w in row.split()]
        kind, n_tags = v[1], v[2]
        physical, tags = v[3], v[3 + n_tags:]
        if kind == 1:
            lines.append((physical, tags))
        elif kind in (2, 3):
            cells.append((physical, tags))
    return nodes, cells, lines


def write_inp(path, nodes, cells, lines, split=False):
    """Abaqus deck: bodies as element sets BODY_1, BODY_2 (also given in
    *Element lines by type), outer sides as node sets, contact sides as
    element-face surfaces. With split, the data lines in files of their
    own as large models are written: "*Node" followed by "*Include,
    input=..." (the nodes file), "*Element, type=..., input=..."."""
    base = os.path.splitext(path)[0]

    def data(keyword, suffix, data_lines):
        if not split:
            return [keyword] + data_lines
        name = base + suffix
        with open(name, "w") as f:
            f.write("\n".join(data_lines) + "\n")
        if keyword == "*Node":
            return [keyword, "*Include, input=%s" % os.path.basename(name)]
        return [keyword + ", input=%s" % os.path.basename(name)]

    out = ["*Heading", "** written by tests/drivers/mesh_formats.py"]
    out += data("*Node", "_nodes.inp",
                ["%d, %.17g, %.17g" % (t, x, y) for t, (x, y) in nodes.items()])
    for n, kind in ((3, "CPE3"), (4, "CPE4R")):
        numbered = [(e + 1, c) for e, c in enumerate(cells)
                    if len(c[1]) == n]
        if numbered:
            out += data("*Element, type=%s" % kind, "_%s.inp" % kind,
                        ["%d, %s" % (e, ", ".join(map(str, c[1])))
                         for e, c in numbered])
    for body in sorted({c[0] for c in cells}):
        out.append("*Elset, elset=BODY_%d" % body)
        out += ["%d," % (e + 1) for e, c in enumerate(cells) if c[0] == body]
    for side in sorted({l[0] for l in lines}):
        edges = [l[1] for l in lines if l[0] == side]
        if side in (5, 6):
            out.append("*Surface, type=ELEMENT, name=SIDE_%d" % side)
            for a, b in edges:
                for e, (_, c) in enumerate(cells):
                    for k in range(len(c)):
                        if {c[k], c[(k + 1) % len(c)]} == {a, b}:
                            out.append("%d, S%d" % (e + 1, k + 1))
        else:
            out.append("*Nset, nset=SIDE_%d" % side)
            out += ["%d," % t for t in sorted({t for e in edges for t in e})]
    out += ["*Solid Section, elset=BODY_1, material=SOFT",
            "*Solid Section, elset=BODY_2, material=STIFF"]
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def write_inp_parts(path, nodes, cells, lines, include=True):
    """Abaqus deck as Abaqus/CAE writes a contact model, by hand from the
    keywords' documented layout: one *Part per body with its own node and
    element numbers from 1 and its own coordinates, an *Assembly with one
    *Instance per part (the lower block translated, the upper block rotated
    by 90 degrees about the z axis through (0.5, 1.5) and translated by
    zero), part sets (BOTTOM of the lower part, found through its only
    instance; TOP of the upper, named Upper-1.TOP in the scene), surfaces of
    the assembly from internal element sets with instance= (the contact
    sides, and LEFT and RIGHT over both instances), *Solid Section per part
    (material ids 1 and 2 in file order), *Material with *Elastic, a *Step,
    a keyword line continued after a comma, and the assembly in a second
    file read through *Include (or in the deck if not include)."""
    parts = {1: "Lower", 2: "Upper"}
    side_names = {1: "LEFT", 2: "RIGHT", 3: "BOTTOM", 4: "TOP",
                  5: "CONTACT_LOWER", 6: "CONTACT_UPPER"}
    out = ["*Heading", "** written by tests/drivers/mesh_formats.py",
           "*Preprint, echo=NO, model=NO,", " history=NO, contact=NO"]
    local = {}  # body -> ({global node: local node}, {cell index: local})
    faces = {}  # side -> [(body, local element, face number)]
    for body, name in parts.items():
        body_cells = [(e, c) for e, c in enumerate(cells) if c[0] == body]
        body_nodes = sorted({t for _, c in body_cells for t in c[1]})
        node_of = {t: i + 1 for i, t in enumerate(body_nodes)}
        element_of = {e: i + 1 for i, (e, _) in enumerate(body_cells)}
        local[body] = (node_of, element_of)
        out += ["*Part, name=%s" % name, "*Node"]
        for t in body_nodes:
            x, y = nodes[t]
            if body == 1:
                # Instance Lower-1 is translated by (0, -5, 0).
                x, y = x, y + 5.0
            else:
                # Instance Upper-1 is rotated by +90 degrees about
                # (0.5, 1.5): the part holds the body turned by -90.
                x, y = 0.5 + (y - 1.5), 1.5 - (x - 0.5)
            out.append("%d, %.17g, %.17g" % (node_of[t], x, y))
        for n, kind in ((3, "CPE3"), (4, "CPE4R")):
            members = [(element_of[e], c) for e, c in body_cells
                       if len(c[1]) == n]
            if members:
                out.append("*Element, type=%s" % kind)
                out += ["%d, %s" % (i, ", ".join(str(node_of[t])
                                                 for t in c[1]))
                        for i, c in members]
        out += ["*Elset, elset=%s_BODY, generate" % name.upper(),
                "1, %d, 1" % len(body_cells)]
        for side, tag in ((3, "BOTTOM"), (4, "TOP")):
            side_nodes = sorted({node_of[t] for l in lines if l[0] == side
                                 for t in l[1] if t in node_of})
            if side_nodes:
                out.append("*Nset, nset=%s" % tag)
                out += ["%d," % t for t in side_nodes]
        out += ["** Section: %s" % name,
                "*Solid Section, elset=%s_BODY, material=M%d" % (
                    name.upper(), body), ",", "*End Part"]
        for side in (1, 2, 5, 6):
            for a, b in [l[1] for l in lines if l[0] == side]:
                for e, (_, c) in body_cells:
                    for k in range(len(c)):
                        if {c[k], c[(k + 1) % len(c)]} == {a, b}:
                            faces.setdefault(side, []).append(
                                (body, element_of[e], k + 1))
    assembly = ["*Assembly, name=Assembly", "*Instance, name=Lower-1, "
                "part=Lower", "0., -5., 0.", "*End Instance",
                "*Instance, name=Upper-1, part=Upper", "0., 0., 0.",
                "0.5, 1.5, 0., 0.5, 1.5, 1., 90.", "*End Instance"]
    for side in (1, 2, 5, 6):
        name = side_names[side]
        lines_of_surface = []
        for body in (1, 2):
            for k in range(1, 5):
                members = [e for b, e, f in faces[side] if b == body and
                           f == k]
                if members:
                    elset = "_%s_S%d_%s" % (name, k, parts[body])
                    assembly += ["*Elset, elset=%s, internal, instance=%s-1"
                                 % (elset, parts[body])]
                    assembly += ["%d," % e for e in members]
                    lines_of_surface.append("%s, S%d" % (elset, k))
        assembly += ["*Surface, type=ELEMENT, name=%s" % name]
        assembly += lines_of_surface
    assembly.append("*End Assembly")
    if include:
        name = os.path.splitext(path)[0] + "_assembly.inp"
        with open(name, "w") as f:
            f.write("\n".join(assembly) + "\n")
        out.append("*Include, input=%s" % os.path.basename(name))
    else:
        out += assembly
    out += ["*Material, name=M1", "*Elastic", "1e9, 0.3",
            "*Material, name=M2", "*Elastic", "3e9, 0.2",
            "*Step, name=Load, nlgeom=NO", "*Static", "1., 1., 1e-05, 1.",
            "*End Step"]
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def write_vtk(path, nodes, cells, lines):
    index = {t: i for i, t in enumerate(nodes)}
    all_cells = cells + lines
    out = ["# vtk DataFile Version 3.0", "mesh_formats.py", "ASCII",
           "DATASET UNSTRUCTURED_GRID", "POINTS %d double" % len(nodes)]
    out += ["%.17g %.17g 0" % p for p in nodes.values()]
    out.append("CELLS %d %d" % (len(all_cells),
                                sum(len(c[1]) + 1 for c in all_cells)))
    for _, tags in all_cells:
        # Gmsh and VTK both run round a quadrilateral.
        out.append(" ".join(map(str, [len(tags)] + [index[t] for t in tags])))
    out.append("CELL_TYPES %d" % len(all_cells))
    out += [str({2: 3, 3: 5, 4: 9}[len(c[1])]) for c in all_cells]
    out += ["CELL_DATA %d" % len(all_cells), "SCALARS MaterialID int 1",
            "LOOKUP_TABLE default"]
    out += [str(c[0]) for c in all_cells]
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def write_vtk42_binary(path, nodes, cells, lines, point_type):
    """Legacy VTK 4.2, BINARY, written from the format's documented layout:
    big-endian values right after each keyword line, CELLS as counts and
    vertices (int), points as float or double, MaterialID as SCALARS int
    with a lookup table, and a POINT_DATA vector field that the reader must
    skip."""
    index = {t: i for i, t in enumerate(nodes)}
    all_cells = cells + lines
    code = {"float": "f", "double": "d"}[point_type]
    out = [b"# vtk DataFile Version 4.2\nmesh_formats.py\nBINARY\n"
           b"DATASET UNSTRUCTURED_GRID\n",
           b"POINTS %d %s\n" % (len(nodes), point_type.encode()),
           struct.pack(">%d%s" % (3 * len(nodes), code),
                       *[v for p in nodes.values() for v in (p[0], p[1], 0)]),
           b"\n"]
    ints = []
    for _, tags in all_cells:
        ints += [len(tags)] + [index[t] for t in tags]
    out += [b"CELLS %d %d\n" % (len(all_cells), len(ints)),
            struct.pack(">%di" % len(ints), *ints), b"\n",
            b"CELL_TYPES %d\n" % len(all_cells),
            struct.pack(">%di" % len(all_cells),
                        *[{2: 3, 3: 5, 4: 9}[len(c[1])] for c in all_cells]),
            b"\n", b"CELL_DATA %d\n" % len(all_cells),
            b"SCALARS MaterialID int 1\nLOOKUP_TABLE default\n",
            struct.pack(">%di" % len(all_cells), *[c[0] for c in all_cells]),
            b"\n", b"POINT_DATA %d\n" % len(nodes),
            b"VECTORS displacement double\n",
            struct.pack(">%dd" % (3 * len(nodes)), *([0.5] * 3 * len(nodes))),
            b"\n"]
    with open(path, "wb") as f:
        f.write(b"".join(out))


def write_ucd(path, nodes, cells, lines):
    """AVS UCD: counts, nodes, then tri/quad cells (material) and line
    cells (boundary id)."""
    out = ["# written by tests/drivers/mesh_formats.py",
           "%d %d 0 0 0" % (len(nodes), len(cells) + len(lines))]
    out += ["%d %.17g %.17g 0" % (t, x, y) for t, (x, y) in nodes.items()]
    kinds = {2: "line", 3: "tri", 4: "quad"}
    for i, (physical, tags) in enumerate(cells + lines):
        out.append("%d %d %s %s" % (i + 1, physical, kinds[len(tags)],
                                    " ".join(map(str, tags))))
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def write_vtu(path, nodes, cells, lines, encoding):
    """VTK XML unstructured grid, its DataArrays written as VTK writes
    them: 'ascii'; 'binary' (base64, header and data encoded apart, UInt32
    header, as VTK); 'binary1' (header and data one base64 stream, UInt64
    header, as other writers); 'zlib' (base64 of zlib blocks, UInt64
    header, blocks of 512 bytes so that the larger arrays take several);
    'appended' (raw appended data, UInt32 header)."""
    index = {t: i for i, t in enumerate(nodes)}
    all_cells = cells + lines
    offsets, connectivity = [], []
    for _, tags in all_cells:
        connectivity += [index[t] for t in tags]
        offsets.append(len(connectivity))
    arrays = [("Points", "Points", "Float64", 3,
               [v for p in nodes.values() for v in (p[0], p[1], 0.0)]),
              ("Cells", "connectivity", "Int64", 1, connectivity),
              ("Cells", "offsets", "Int64", 1, offsets),
              ("Cells", "types", "UInt8", 1,
               [{2: 3, 3: 5, 4: 9}[len(c[1])] for c in all_cells]),
              ("CellData", "MaterialID", "Int32", 1,
               [c[0] for c in all_cells])]
    codes = {"Float64": "d", "Int64": "q", "UInt8": "B", "Int32": "i"}
    header = "Q" if encoding in ("zlib", "binary1") else "I"
    appended = b""
    sections = {}
    for section, name, kind, n_components, values in arrays:
        data = struct.pack("<%d%s" % (len(values), codes[kind]), *values)
        attributes = 'type="%s" Name="%s" NumberOfComponents="%d"' % (
            kind, name, n_components)
        if encoding == "ascii":
            body = " ".join(repr(v) for v in values)
            attributes += ' format="ascii"'
        elif encoding == "binary":
            body = (base64.b64encode(struct.pack("<I", len(data))) +
                    base64.b64encode(data)).decode()
            attributes += ' format="binary"'
        elif encoding == "binary1":
            body = base64.b64encode(struct.pack("<Q", len(data)) +
                                    data).decode()
            attributes += ' format="binary"'
        elif encoding == "zlib":
            blocks = [zlib.compress(data[i:i + 512])
                      for i in range(0, len(data), 512)]
            last = len(data) % 512
            head = struct.pack("<%dQ" % (3 + len(blocks)), len(blocks),
                               512, last, *map(len, blocks))
            body = (base64.b64encode(head) +
                    base64.b64encode(b"".join(blocks))).decode()
            attributes += ' format="binary"'
        else:
            attributes += ' format="appended" offset="%d"' % len(appended)
            appended += struct.pack("<I", len(data)) + data
            body = ""
        sections.setdefault(section, []).append(
            "<DataArray %s>%s</DataArray>" % (attributes, body))
    text = ('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" '
            'version="1.0" byte_order="LittleEndian" header_type="%s"%s>\n'
            % ("UInt64" if header == "Q" else "UInt32",
               ' compressor="vtkZLibDataCompressor"'
               if encoding == "zlib" else ""))
    text += ('<UnstructuredGrid>\n<Piece NumberOfPoints="%d" '
             'NumberOfCells="%d">\n' % (len(nodes), len(all_cells)))
    for section in ("Points", "Cells", "CellData"):
        text += "<%s>\n%s\n</%s>\n" % (section,
                                          "\n".join(sections[section]),
                                          section)
    text += "</Piece>\n</UnstructuredGrid>\n"
    with open(path, "wb") as f:
        f.write(text.encode())
        if encoding == "appended":
            f.write(b'<AppendedData encoding="raw">\n_' + appended +
                    b"\n</AppendedData>\n")
        f.write(b"</VTKFile>\n")


# The boundary ids of the scene: patch_stack.geo's physical curves.
PHYSICAL_IDS = dict(bottom="3", sides="1, 2", top="4", slave="6", master="5")


def run(binary, folder, name, mesh, sets, pictures=False):
    out = os.path.join(folder, name)
    scene = os.path.join(folder, name + ".prm")
    with open(scene, "w") as f:
        f.write(SCENE.format(file=mesh, folder=out,
                             pictures="true" if pictures else "false",
                             element_sets=sets[0], boundary_sets=sets[1],
                             **PHYSICAL_IDS))
    result = subprocess.run([binary, scene], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    if result.returncode != 0:
        print(result.stdout[-3000:])
        raise SystemExit("%s: exit code %d" % (name, result.returncode))
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out, "contact_blocks.csv")) as f:
        rows = sorted((tuple(float(v) for v in row.values()
                             if v.replace(".", "").replace("-", "")
                             .replace("e", "").replace("+", "").isdigit())
                       for row in csv.DictReader(f)))
    return summary, rows


def numbers(value, path=""):
    """(path, number) for every number in summary.json but the timings."""
    if isinstance(value, dict):
        for k, v in value.items():
            if k not in ("wall_time", "solver"):
                yield from numbers(v, path + "/" + k)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from numbers(v, path + "[%d]" % i)
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        yield path, float(value)


def compare(name, reference, other):
    failures = 0
    a, b = dict(numbers(reference[0])), dict(numbers(other[0]))
    assert a.keys() == b.keys(), (name, a.keys() ^ b.keys())
    scale = max(abs(v) for v in a.values())
    worst = 0
    for key in a:
        top = key.split("/")[1]
        if top in ("equilibrium_residual", "relative_max_penetration",
                   "complementarity_residual"):
            # Relative round-off measures (1e-16 in a file whose
            # coordinates differ in the last digit): compared absolutely.
            reference_scale = 1.0
        elif top == "max_penetration":
            reference_scale = abs(a["/max_displacement"])
        else:
            # Relative to the largest number of its kind (forces,
            # stresses...).
            reference_scale = max(abs(v) for k, v in a.items()
                                  if k.split("/")[1] == top)
        error = abs(a[key] - b[key]) / max(reference_scale, 1e-300 * scale)
        worst = max(worst, error)
        if error > TOLERANCE:
            print("FAIL %s: %s = %r, .msh gives %r" % (name, key, b[key],
                                                     a[key]))
            failures += 1
    assert len(reference[1]) == len(other[1]) > 0
    for ra, rb in zip(reference[1], other[1]):
        rscale = max(max(abs(v) for v in ra), 1e-300)
        worst = max(worst, max(abs(x - y) for x, y in zip(ra, rb)) / rscale)
        if max(abs(x - y) for x, y in zip(ra, rb)) > TOLERANCE * rscale:
            print("FAIL %s: contact row %r, .msh gives %r" % (name, rb, ra))
            failures += 1
    print("%s: %d numbers and %d contact pairs, largest relative "
          "difference to .msh %.1e (tolerance %.0e)"
          % (name, len(a), len(reference[1]), worst, TOLERANCE))
    return failures


def main():
    binary = os.path.abspath(sys.argv[1])
    failures = 0
    with tempfile.TemporaryDirectory() as folder:
        for kind, arguments in (("triangles", []),
                                ("mixed", ["-setnumber", "mixed", "1"])):
            msh = os.path.join(folder, kind + ".msh")
            subprocess.run(["gmsh", "-2", "-format", "msh22", GEO, "-o", msh]
                           + arguments, check=True, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
            nodes, cells, lines = read_msh22(msh)
            sizes = {len(c[1]) for c in cells}
            assert sizes == ({3} if kind == "triangles" else {3, 4}), sizes
            inp = os.path.join(folder, kind + ".inp")
            vtk = os.path.join(folder, kind + ".vtk")
            write_inp(inp, nodes, cells, lines)
            write_vtk(vtk, nodes, cells, lines)
            no_sets = ("", "")
            abaqus_sets = ("BODY_1: 1; BODY_2: 2",
                           "; ".join("SIDE_%d: %d" % (i, i)
                                     for i in range(1, 7)))
            reference = run(binary, folder, kind + "_msh", msh, no_sets,
                            pictures=True)
            for picture in ("deformation.png", "stress_yy.png",
                            "contact_pressure.png"):
                assert os.path.getsize(os.path.join(
                    folder, kind + "_msh", picture)) > 1000, picture
            print("%s: %d cells read (%s), %d after splitting; analytic "
                  "checks pass; pictures drawn"
                  % (kind, len(cells), "P1" if kind == "triangles" else
                     "mixed, split into quadrilaterals",
                     reference[0]["n_cells"]))
            abaqus = run(binary, folder, kind + "_inp", inp, abaqus_sets,
                         pictures=True)
            for picture in ("deformation.png", "stress_yy.png",
                            "contact_pressure.png"):
                assert os.path.getsize(os.path.join(
                    folder, kind + "_inp", picture)) > 1000, picture
            failures += compare(kind + ".inp", reference, abaqus)
            # Nodes through *Include inside the *Node block, elements
            # through *Element, input=: the same mesh.
            split_inp = os.path.join(folder, kind + "_split.inp")
            write_inp(split_inp, nodes, cells, lines, split=True)
            failures += compare(kind + ".inp, nodes by *Include, elements "
                                "by input=", reference,
                                run(binary, folder, kind + "_split_inp",
                                    split_inp, abaqus_sets))
            failures += compare(kind + ".vtk", reference,
                                run(binary, folder, kind + "_vtk", vtk,
                                    no_sets))
            # The model as Abaqus/CAE writes it: parts, instances moved,
            # surfaces of the assembly over two instances.
            parts_inp = os.path.join(folder, kind + "_parts.inp")
            write_inp_parts(parts_inp, nodes, cells, lines)
            parts_sets = ("", "LEFT: 1; RIGHT: 2; BOTTOM: 3; Upper-1.TOP: 4; "
                              "CONTACT_LOWER: 5; CONTACT_UPPER: 6")
            failures += compare(kind + ".inp of parts and instances",
                                reference,
                                run(binary, folder, kind + "_parts_inp",
                                    parts_inp, parts_sets))
            # Gmsh's own Abaqus export (an independent writer: physical
            # curves as T3D2 line elements, sets named Physical...).
            gmsh_inp = os.path.join(folder, kind + "_gmsh.inp")
            subprocess.run(["gmsh", "-2", "-format", "inp", GEO, "-o",
                            gmsh_inp] + arguments, check=True,
                           stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
            gmsh_sets = ("PhysicalSurface1: 1; PhysicalSurface2: 2",
                         "; ".join("PhysicalLine%d: %d" % (i, i)
                                   for i in range(1, 7)))
            failures += compare(kind + ".inp (written by gmsh)", reference,
                                run(binary, folder, kind + "_gmsh_inp",
                                    gmsh_inp, gmsh_sets))
            ucd = os.path.join(folder, kind + ".ucd")
            write_ucd(ucd, nodes, cells, lines)
            failures += compare(kind + ".ucd", reference,
                                run(binary, folder, kind + "_ucd", ucd,
                                    no_sets))
            for encoding in ("ascii", "binary", "binary1", "zlib",
                             "appended"):
                vtu = os.path.join(folder, kind + "_" + encoding + ".vtu")
                write_vtu(vtu, nodes, cells, lines, encoding)
                failures += compare(
                    "%s.vtu (%s)" % (kind, encoding), reference,
                    run(binary, folder, kind + "_vtu_" + encoding, vtu,
                        no_sets))
            # Entities in two physical groups (Gmsh allows it; deal.II 9.4
            # refuses more than one tag): the contact sides and the top
            # also in curve group 7 and both blocks in surface group 3,
            # which the scene does not name, in both .msh versions.
            for version in ("msh22", "msh41"):
                path = os.path.join(folder, "%s_groups_%s.msh" % (kind,
                                                                  version))
                subprocess.run(["gmsh", "-2", "-format", version, GEO, "-o",
                                path, "-setnumber", "groups", "1"] + arguments,
                               check=True, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
                failures += compare(
                    "%s .%s with entities in two physical groups"
                    % (kind, version), reference,
                    run(binary, folder, "%s_groups_%s" % (kind, version),
                        path, no_sets))
            # Binary .msh 4.1 (gmsh -bin), which deal.II 9.4 reads only
            # through the Gmsh API: converted by the gmsh program.
            path = os.path.join(folder, kind + "_binary.msh")
            subprocess.run(["gmsh", "-2", "-format", "msh41", "-bin", GEO,
                            "-o", path] + arguments, check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            with open(path, "rb") as f:
                assert f.read().split(b"\n")[1].split()[1] == b"1", path
            failures += compare("%s .msh 4.1 binary" % kind, reference,
                                run(binary, folder, kind + "_binary_msh",
                                    path, no_sets))
            # Legacy VTK as other programs write it: meshio (the 5.1 layout,
            # ASCII and binary, ids in a FIELD array gmsh:physical; and its
            # zlib .vtu), gmsh's own export (2.0 layout, ASCII and binary,
            # physical groups as CellEntityIds), and the 4.2 binary
            # layout written here from the format's description.
            import meshio
            mesh = meshio.read(msh)
            for name, options in (("meshio_ascii.vtk", dict(binary=False)),
                                  ("meshio_binary.vtk", dict(binary=True)),
                                  ("meshio.vtu", {})):
                path = os.path.join(folder, kind + "_" + name)
                meshio.write(path, mesh, **options)
                failures += compare(
                    "%s %s (written by meshio %s)" % (kind, name,
                                                     meshio.__version__),
                    reference,
                    run(binary, folder, kind + "_" + name.replace(".", "_"),
                        path, no_sets))
            for name, options in (("gmsh_ascii.vtk", []),
                                  ("gmsh_binary.vtk", ["-bin"])):
                path = os.path.join(folder, kind + "_" + name)
                subprocess.run(["gmsh", "-2", "-format", "vtk", GEO, "-o",
                                path] + options + arguments, check=True,
                               stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
                failures += compare(
                    "%s %s (written by gmsh)" % (kind, name), reference,
                    run(binary, folder, kind + "_" + name.replace(".", "_"),
                        path, no_sets))
            # VTK 9 itself (python3-vtk9): the legacy writer of the format's
            # owner, 5.1 ASCII with METADATA blocks (a component name, the
            # points' norm range) that the reader must skip, 5.1 binary and
            # 4.2 binary, from meshio's .vtu read by VTK's XML reader.
            import vtk
            reader = vtk.vtkXMLUnstructuredGridReader()
            reader.SetFileName(os.path.join(folder, kind + "_meshio.vtu"))
            reader.Update()
            grid = reader.GetOutput()
            grid.GetCellData().GetArray("gmsh:physical").SetComponentName(
                0, "physical group")
            grid.GetPoints().GetData().GetRange(-1)
            for name, version, binary_file in (("51_ascii", 51, False),
                                               ("51_binary", 51, True),
                                               ("42_binary", 42, True)):
                path = os.path.join(folder, "%s_vtk9_%s.vtk" % (kind, name))
                writer = vtk.vtkUnstructuredGridWriter()
                writer.SetFileName(path)
                writer.SetInputData(grid)
                writer.SetFileVersion(version)
                if binary_file:
                    writer.SetFileTypeToBinary()
                writer.Write()
                with open(path, "rb") as f:
                    assert version == 42 or b"METADATA" in f.read(), path
                written = "%s .vtk %s (written by VTK %s)" % (
                    kind, name, vtk.vtkVersion.GetVTKVersion())
                result = run(binary, folder, "%s_vtk9_%s" % (kind, name),
                             path, no_sets)
                if binary_file:
                    failures += compare(written, reference, result)
                else:
                    # VTK writes ASCII coordinates to 6 digits: the mesh
                    # moves, so only the analytic checks (exit code 0 in
                    # run()) apply.
                    print("%s: analytic checks pass" % written)
            path = os.path.join(folder, kind + "_42_double.vtk")
            write_vtk42_binary(path, nodes, cells, lines, "double")
            failures += compare("%s .vtk 4.2 binary" % kind, reference,
                                run(binary, folder, kind + "_42_double",
                                    path, no_sets))
            # Float points: the mesh moves by round-off, so only the
            # analytic checks (run() requires exit code 0) apply.
            path = os.path.join(folder, kind + "_42_float.vtk")
            write_vtk42_binary(path, nodes, cells, lines, "float")
            run(binary, folder, kind + "_42_float", path, no_sets)
            print("%s .vtk 4.2 binary, float points: analytic checks pass"
                  % kind)
    if failures:
        raise SystemExit("%d differences" % failures)


if __name__ == "__main__":
    main()
