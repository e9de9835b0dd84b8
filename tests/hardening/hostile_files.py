#!/usr/bin/python3
"""Hostile files of the third hardening round, each run alone with its time
and peak memory measured (wait4): files far larger than they look (sparse
files of 4.3 GB declaring arrays of 179 million points, or holding nothing
but zeros), XML and scene files nested 30 000 to 100 000 levels deep, and
Abaqus decks whose data come from other files. Each case must end with the
exit code and the one-line message given here (or run to exit 0 where the
input is valid), within its time and memory bound; before this round they
crashed (the XML nesting), took 100 s and 5.7 GB (the sparse VTK file) or
15 s and 1.1 GB (the nested scene).

The bounds are generous (the machine is noisy and sanitizer builds are 3-5
times slower and map more): a refusal must come before the file is read,
so the bound is a few seconds and a few hundred MB, where reading would
take minutes and gigabytes.

Usage: hostile_files.py KNEE_CONTACT [SANITIZED (ON/OFF)]
"""
import os
import re
import subprocess
import sys
import tempfile
import time

SCENE = """subsection Mesh
  set Source = file
  set File   = {file}
end
subsection Materials
  subsection Material 0
    set Material id = 1
  end
end
"""
GB = 4300000000
N = 179000000  # points of 24 bytes: a 4.3 GB array


def sparse(head, size=GB, tail=b""):
    """A file of head, a hole up to size, then tail."""
    return (head, size, tail)


VTU_HEAD = (b'<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" '
            b'version="0.1"><UnstructuredGrid><Piece NumberOfPoints="%d" '
            b'NumberOfCells="1">')

CASES = [
    # (name, scene file name, files {name: bytes | sparse()}, exit code,
    #  regex of the one line on stderr)
    ("VTU, elements nested 100 000 deep", "scene.prm",
     {"scene.prm": SCENE.format(file="m.vtu").encode(),
      "m.vtu": VTU_HEAD % 1000 + b'<a x="1>2">' * 100000 + b"</a>" * 100000
      + b"</Piece></UnstructuredGrid></VTKFile>\n"}, 1,
     r"Mesh/File: '.*m\.vtu': line 2: XML elements nested deeper than 64 "
     r"levels \(a VTU file needs 6"),
    ("VTU, sparse, 179e6 points in 4.3 GB of appended data", "scene.prm",
     {"scene.prm": SCENE.format(file="m.vtu").encode(),
      "m.vtu": sparse(VTU_HEAD % N + b'<Points><DataArray type="Float64" '
                      b'NumberOfComponents="3" format="appended" offset="0"/>'
                      b'</Points></Piece></UnstructuredGrid><AppendedData '
                      b'encoding="raw">_', GB,
                      b"</AppendedData></VTKFile>\n")}, 1,
     r"Mesh/File: '.*m\.vtu': NumberOfPoints 179000000, NumberOfCells 1: "
     r"about 8\.95e\+07 cells need about 716 GB; .* are available"),
    ("VTU, 3 points, then 4.3 GB of zero bytes", "scene.prm",
     {"scene.prm": SCENE.format(file="m.vtu").encode(),
      "m.vtu": sparse(VTU_HEAD % 3)}, 1,
     r"Mesh/File: '.*m\.vtu': the file's 4300000000 bytes are more than 3 "
     r"points and 1 cells take \(at most 1064960: 4 kB each and 1 MB\)"),
    (".geo, 4.3 GB", "scene.prm",
     {"scene.prm": SCENE.format(file="m.geo").encode(),
      "m.geo": sparse(b"Point(1) = {0, 0, 0};\n")}, 1,
     r"Mesh/File: '.*m\.geo' is larger than 64 MB, the most a \.geo script "
     r"may be"),
    ("legacy VTK, sparse, BINARY POINTS of 4.3 GB", "scene.prm",
     {"scene.prm": SCENE.format(file="m.vtk").encode(),
      "m.vtk": sparse(b"# vtk DataFile Version 4.2\ntitle\nBINARY\nDATASET "
                      b"UNSTRUCTURED_GRID\nPOINTS %d double\n" % N)}, 1,
     r"Mesh/File: '.*m\.vtk' line 5: POINTS 179000000: about 8\.95e\+07 "
     r"cells need about 716 GB; .* are available"),
    ("legacy VTK, ASCII, 4.3 GB of zero bytes after POINTS", "scene.prm",
     {"scene.prm": SCENE.format(file="m.vtk").encode(),
      "m.vtk": sparse(b"# vtk DataFile Version 4.2\ntitle\nASCII\nDATASET "
                      b"UNSTRUCTURED_GRID\nPOINTS 3 double\n")}, 1,
     r"Mesh/File: '.*m\.vtk' line 6: a word of more than 256 characters "
     r"where a number should be"),
    ("legacy VTK, 4.3 GB without a line end", "scene.prm",
     {"scene.prm": SCENE.format(file="m.vtk").encode(),
      "m.vtk": sparse(b"# vtk DataFile Version 4.2\n")}, 1,
     r"Mesh/File: '.*m\.vtk' line 2: a line longer than 1024 kB where a "
     r"keyword should be"),
    ("UCD, 4.3 GB of zero bytes", "scene.prm",
     {"scene.prm": SCENE.format(file="m.ucd").encode(),
      "m.ucd": sparse(b"# ucd\n")}, 1,
     r"Mesh/File: '.*m\.ucd' line 2: a line longer than 1024 kB"),
    ("Abaqus, 4.3 GB of zero bytes", "scene.prm",
     {"scene.prm": SCENE.format(file="m.inp").encode(),
      "m.inp": sparse(b"*Heading\n")}, 1,
     r"Mesh/File: '.*m\.inp' line 2: a line longer than 1024 kB"),
    (".msh, sparse, 179e6 nodes declared", "scene.prm",
     {"scene.prm": SCENE.format(file="m.msh").encode(),
      "m.msh": sparse(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n"
                      % N)}, 1,
     r"Mesh/File: '.*m\.msh' line 5: 179000000 nodes: about 8\.95e\+07 "
     r"cells need about 716 GB"),
    (".msh, 4.3 GB without a line end", "scene.prm",
     {"scene.prm": SCENE.format(file="m.msh").encode(),
      "m.msh": sparse(b"$MeshFormat\n")}, 1,
     r"Mesh/File: '.*m\.msh' line 2: a line longer than 1024 kB"),
    ("Abaqus, *Node, input= a file that is not there", "scene.prm",
     {"scene.prm": SCENE.format(file="m.inp").encode(),
      "m.inp": b"*Heading\n*Node, input=nodes.inp\n"}, 1,
     r"Mesh/File: '.*m\.inp' line 2: INPUT=nodes.inp: cannot open "
     r"'.*nodes\.inp'"),
    ("Abaqus, *Include of itself inside *Node", "scene.prm",
     {"scene.prm": SCENE.format(file="m.inp").encode(),
      "m.inp": b"*Heading\n*Node\n*Include, input=m.inp\n"}, 1,
     r"Mesh/File: '.*m\.inp' line 3: INPUT=m.inp, which includes itself"),
    ("scene, 30 000 nested subsections", "scene.prm",
     {"scene.prm": b"".join(b"subsection a%d\n" % i for i in range(30000))
      + b"end\n" * 30000}, 1,
     r"scene\.prm:17: subsections nested deeper than 16 levels"),
    ("JSON scene, objects nested 100 000 deep", "scene.json",
     {"scene.json": b"{" + b'"a":{' * 100000 + b"}" * 100001}, 1,
     r"scene\.json: subsections nested deeper than 16 levels"),
    ("JSON scene, arrays nested 100 000 deep", "scene.json",
     {"scene.json": b'{"Mesh": ' + b"[" * 100000 + b"]" * 100000 + b"}"}, 1,
     r"scene\.json: subsections nested deeper than 16 levels"),
    ("scene, sparse, 4.3 GB", "scene.prm",
     {"scene.prm": sparse(b"# a scene\n")}, 1,
     r"scene\.prm: 4100 MB; a scene file is at most 16 MB"),
]


def write(folder, files):
    for name, content in files.items():
        with open(os.path.join(folder, name), "wb") as f:
            if isinstance(content, tuple):
                head, size, tail = content
                f.write(head)
                f.truncate(size)
                f.seek(0, 2)
                f.write(tail)
            else:
                f.write(content)


def run(program, folder, scene):
    """Exit code, stderr, seconds and peak resident MB of one run."""
    start = time.monotonic()
    with open(os.path.join(folder, "stderr"), "wb") as err:
        p = subprocess.Popen([program, scene], cwd=folder,
                             stdout=subprocess.DEVNULL, stderr=err)
        try:
            _, status, usage = os.wait4(p.pid, 0)
        finally:
            p.returncode = 0
    seconds = time.monotonic() - start
    code = os.waitstatus_to_exitcode(status)
    text = open(os.path.join(folder, "stderr"), encoding="utf-8",
                errors="replace").read()
    return code, text, seconds, usage.ru_maxrss / 1024


def main():
    program = os.path.abspath(sys.argv[1])
    sanitized = len(sys.argv) > 2 and sys.argv[2] == "ON"
    seconds_bound, megabytes_bound = (30, 3000) if sanitized else (10, 600)
    failures = 0
    for name, scene, files, expected_code, regex in CASES:
        with tempfile.TemporaryDirectory() as folder:
            write(folder, files)
            code, err, seconds, megabytes = run(program, folder, scene)
        lines = err.splitlines()
        problem = None
        if code != expected_code:
            problem = "exit code %d, expected %d" % (code, expected_code)
        elif expected_code != 0 and (len(lines) != 1 or
                                     not re.search(regex, lines[0])):
            problem = "stderr does not match %r" % regex
        elif seconds > seconds_bound or megabytes > megabytes_bound:
            problem = "over the bound of %d s and %d MB" % (seconds_bound,
                                                             megabytes_bound)
        print("%s %s: exit %d in %.2f s, %.0f MB peak: %s"
              % ("FAIL" if problem else "PASS", name, code, seconds,
                 megabytes, err.strip()[-300:]))
        if problem:
            print("  ", problem)
            failures += 1
    print("%d of %d hostile files handled" % (len(CASES) - failures,
                                               len(CASES)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
