#!/usr/bin/python3
"""Runs under mpirun against the one-process run of the same scene.

1. Each scene of SCENES runs as one process (no mpirun) and under
   `mpirun -np N`. Asserted, relative to the largest value of its kind in
   the one-process run: every number of summary.json (energy, reactions,
   forces, pressures, stresses, areas, stick and slip counts, per load
   case too) to 1e-8; the displacement of every vertex (solution.vtu,
   floats: beyond one float32 unit) to 1e-8 of max |u|, its cells, bodies
   and points equal in sorted order (the ranks build its pieces, rank 0
   writes them; on the distributed mesh each rank's cells, so in another
   order: DISTRIBUTED, asserted); every contact CSV column to 1e-8 of
   its largest value,
   and its flags (active, stick or slip, the discretisation) equal. The error
   bars (influence solves stopped at a hundredth of their start residual)
   to 1e-2 of the largest bar.
   The distributed iterative path (Contact/Solver = iterative: CG and AMG
   over the ranks, here to 1e-14 of the load: tight_krylov(); with 3D
   friction its Newton springs), the sparse path with MUMPS's factor over
   the ranks (against CHOLMOD's of one process) and the condensed path
   (whole on each rank); adaptive refinement (3D, goal-oriented) and a 2D study of both
   sequences. Measured: at most 1.2e-10 (the 3D knee at 2.3e5 dofs at
   1e-12: 1.1e-11, doc/parallel.md).
   Bodies moved along a frictional path (drivers/motion.py's 3D drag,
   Load cases/Motion) on the distributed iterative path.
2. More ranks than cells on a body and than vertices: a block of one cell
   on a base of 4 x 2 (19 vertices), 24 ranks, the iterative path and the
   sparse path's MUMPS (ranks that own no row still take part in every
   collective operation).
3. Bad input under mpirun, refused as one process refuses it: exit code
   1 and the one process's one-line error, printed once (not once per
   rank): a bad parameter, a mesh refused where it may be distributed
   (rank 0 alone makes and checks it, the other takes its refusal), a
   body no constraint holds (found by all ranks together on the
   distributed mesh) and a .geo gmsh refuses (rank 0 alone runs gmsh, the
   others take its failure); and a mesh too large where it may be distributed, refused by
   the distributed run's estimate ("a rank on the distributed mesh"),
   said once.
Under the sanitizers (SANITIZE = ON) the scenes whose code under mpirun is
that of another scene here are left out (SANITIZER_SKIPS): each run there
is 3 to 7 times slower, and the adaptive Hertz sphere alone took 200 s.
Usage: parallel.py KNEE_CONTACT [SANITIZE]
"""
import csv
import glob
import json
import os
import re
import subprocess
import sys
import tempfile

import numpy
import vtk
from vtk.util.numpy_support import vtk_to_numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import friction  # noqa: E402
import motion  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES_FOLDER = os.path.join(HERE, "..", "scenes")
# (scene of tests/scenes, Contact/Solver or None for the scene's own, ranks,
# [(pattern, replacement)] made in the scene). The 3D sliding block is pushed by 10 m
# there so that its slip directions are equal; its stresses, 1e-5 of that,
# carry the solves' 1e-12 relative to |u| as 1e-7 (one and two ranks
# differed by 1.6e-7 in the energy): here it is pushed by 0.01 m, so that
# the springs of its Newton step and their directions vary (and its
# analytic forces, which assume equal directions, are not checked).
SCENES = [("contact_patch_3d_tet_iterative.prm", None, 2, []),
          ("contact_patch_3d_hex.prm", "iterative", 2, []),
          ("hertz_small.prm", "iterative", 2, []),
          ("knee_small.prm", None, 2, []),
          ("friction_sliding_block.prm", None, 2, []),
          ("friction_sliding_block_3d.prm", "iterative", 2,
           [("9.5533; 2.9552; 0", "0.0095533; 0.0029552; 0"),
            (r"\nsubsection Verification\n(.*\n)*?end\n", "\n")]),
          # MUMPS's factor over the ranks (the sparse path's automatic
          # factor on more than one rank) against CHOLMOD's of one
          # process: a 2D knee, and the 3D block's Newton springs and
          # Coulomb couplings (GMRES on the distributed factor).
          ("knee_small.prm", "sparse", 2, []),
          ("friction_sliding_block_3d.prm", "sparse", 2,
           [("9.5533; 2.9552; 0", "0.0095533; 0.0029552; 0"),
            (r"\nsubsection Verification\n(.*\n)*?end\n", "\n")]),
          ("load_cases_patch.prm", "iterative", 2, []),
          # A uniform sequence of two meshes on the distributed mesh (the
          # second made whole anew, one more refinement, and distributed):
          # the last mesh's results and the sequence's error bars.
          ("hertz_small.prm", "iterative", 2,
           [(r"\nsubsection Contact\n",
             "\nsubsection Refinement\n  set Number of cycles = 2\nend\n"
             "subsection Contact\n")]),
          # The automatic choice on a small 3D mesh, a uniform sequence of
          # two: rank 0 alone makes each cycle's mesh and decides, then,
          # below ContactProblem::min_distributed_dofs, every rank makes it
          # whole.
          ("contact_patch_3d_hex.prm", None, 2,
           [(r"\nsubsection Contact\n",
             "\nsubsection Refinement\n  set Number of cycles = 2\nend\n"
             "subsection Contact\n")]),
          # Refinement: three adaptive cycles of goal-oriented refinement
          # in 3D on the distributed path, and the uniform and adaptive
          # sequences of a 2D study (its last mesh's results) on the
          # direct path.
          ("hertz_sphere_3d_adaptive.prm", "iterative", 2, []),
          ("hertz_study_small.prm", None, 2, [])]
# Left out under the sanitizers: the hexahedral patch and the Hertz
# cylinders on the iterative path (the tetrahedral patch and the 3D block run
# its distributed code), the sphere's adaptive cycles (remeshing and
# goal-oriented estimates are replicated work, the code of one process,
# which the sanitizer stage runs in the adaptive 3D blocks and the 2D
# studies) and the 2D study on the direct path (as knee_small).
SANITIZER_SKIPS = ("contact_patch_3d_hex.prm", "hertz_small.prm",
                   "hertz_sphere_3d_adaptive.prm", "hertz_study_small.prm")
# The runs that take the distributed mesh (one cycle or a .geo remeshed,
# no friction, one load case, the iterative path on several ranks:
# ContactProblem::distribution_reason()); the others keep the whole mesh on
# every rank. Each is asserted (summary.json's solver/distributed_mesh).
DISTRIBUTED = ("contact_patch_3d_tet_iterative", "contact_patch_3d_hex_iterative",
               "hertz_small_iterative", "one_cell_block",
               "friction_sliding_block_3d_iterative",
               "load_cases_patch_iterative", "hertz_small_iterative_uniform")
TOLERANCE = 1e-8
BAR_TOLERANCE = 1e-2
# Round-off measures and what depends on the path taken, not the answer.
SKIPPED = ("wall_time", "solver", "active_set_iterations",
           "equilibrium_residual", "relative_max_penetration",
           "complementarity_residual", "max_penetration",
           # under a uniform pressure every pair ties up to round-off
           "peak_location")
# CSV columns of motions: their scale is max |u| (a closed gap's jump is
# round-off beside it).
MOTIONS = ("gap", "jump", "slip", "accumulated_slip")
FLAGS = ("active",)


def number(text):
    """Whether a CSV field is a number (else a flag such as stick/slip)."""
    try:
        float(text)
        return True
    except ValueError:
        return False


def mpi_environment():
    """Open MPI as root (CI) and on more ranks than cores."""
    env = dict(os.environ)
    env.update({"OMPI_ALLOW_RUN_AS_ROOT": "1",
                "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
                "OMPI_MCA_rmaps_base_oversubscribe": "1"})
    return env


def run(binary, scene, ranks):
    """knee_contact on @p scene, by one process (0 ranks: no mpirun) or
    under mpirun -np @p ranks."""
    command = [binary, scene]
    if ranks:
        command = ["mpirun", "--oversubscribe", "-np", str(ranks)] + command
    return subprocess.run(command, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True,
                          env=mpi_environment(), timeout=600)


def kind(key):
    """The scale of a number: the error bars one kind, the stresses one,
    each quantity of the contact interfaces one (force, max_pressure, ...),
    else its entry (reactions, energy, ...)."""
    parts = key.split("/")
    if "error" in key:
        return "error"
    if "stress" in parts[1] or "mises" in parts[1]:
        return "stress"
    if parts[1] in ("contact_interfaces", "load_cases"):
        return re.sub(r"\[\d+\]", "", parts[-1])
    return re.sub(r"\[\d+\]", "", parts[1])


def worst_difference(name, reference, other, failures):
    """Every number of two summaries, relative to the largest of its kind."""
    a = dict(friction.numbers(reference, skipped=SKIPPED))
    b = dict(friction.numbers(other, skipped=SKIPPED))
    if a.keys() != b.keys():
        failures.append("%s: summary entries differ: %s" % (name,
                                                            a.keys() ^ b.keys()))
        return 0.0
    worst = 0.0
    for key in a:
        scale = max(abs(v) for k, v in a.items() if kind(k) == kind(key))
        error = abs(a[key] - b[key]) / (scale or 1.0)
        tolerance = BAR_TOLERANCE if kind(key) == "error" else TOLERANCE
        if kind(key) != "error":
            worst = max(worst, error)
        if error > tolerance:
            failures.append("%s: %s = %r, one process %r" % (name, key, b[key],
                                                             a[key]))
    return worst


def below(folder, pattern, read):
    """read(path) of every file matching @p pattern below @p folder (one per
    load case), by its path relative to @p folder."""
    return {os.path.relpath(path, folder): read(path)
            for path in sorted(glob.glob(os.path.join(folder, "**", pattern),
                                         recursive=True))}


def read_json(path):
    with open(path) as f:
        return json.load(f)


def read_points(path):
    """The points of a solution.vtu (DataOut writes each cell's own
    vertices), as rows of coordinates, body and displacement sorted by
    coordinates and body: on a distributed mesh each rank writes its own
    cells, so the file's order of cells is not the one process's."""
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    points = vtk_to_numpy(grid.GetPoints().GetData())
    body = vtk_to_numpy(grid.GetPointData().GetArray("body_id"))
    u = vtk_to_numpy(grid.GetPointData().GetArray("displacement"))
    rows = numpy.column_stack([points, body, u])
    order = numpy.lexsort([rows[:, k] for k in range(4)][::-1])
    return rows[order]


def read_displacement(path):
    """The point displacements of a solution.vtu, in read_points()'s
    order."""
    return read_points(path)[:, 4:]


def read_cells(path):
    """The cells of a solution.vtu (under mpirun built in pieces by every
    rank and written by rank 0): their number, and the coordinates and
    bodies of their vertices in read_points()'s order."""
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    return (reader.GetOutput().GetNumberOfCells(),
            read_points(path)[:, :4].tolist())


def read_rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def compare_fields(name, one, many, failures):
    """Displacements and contact tables of two result folders; returns the
    largest relative difference."""
    worst = 0.0
    u1 = below(one, "solution.vtu", read_displacement)
    u2 = below(many, "solution.vtu", read_displacement)
    if not u1 or u1.keys() != u2.keys():
        failures.append("%s: solution.vtu files %s against %s" %
                        (name, sorted(u1), sorted(u2)))
    c1 = below(one, "solution.vtu", read_cells)
    c2 = below(many, "solution.vtu", read_cells)
    for path in c1:
        if path in c2 and c1[path] != c2[path]:
            failures.append("%s: %s: cells, bodies or points differ from the "
                            "one-process file (%d cells against %d)" %
                            (name, path, c2[path][0], c1[path][0]))
    u_scale = max([abs(u).max() for u in u1.values()] + [0.0])
    for path in u1:
        if path in u2:
            # solution.vtu holds float32: two runs whose doubles differ by
            # round-off may round a value to neighbouring floats, one unit
            # in the last place (2^-23 of it) apart; that unit is allowed
            # beside the tolerance (the uniform Hertz sequence differed by
            # one, 1.1e-8 of max |u|, with every double figure of
            # summary.json and the CSVs within 1e-10).
            scale = abs(u1[path]).max() or 1.0
            ulp = 2.0**-23 * numpy.maximum(abs(u1[path]), abs(u2[path]))
            excess = abs(u1[path] - u2[path]) - ulp
            error = max(float(excess.max()), 0.0) / scale
            worst = max(worst, error)
            if error > TOLERANCE:
                failures.append("%s: %s displacement differs by %.1e of max "
                                "|u|" % (name, path, error))
    t1 = below(one, "contact_*.csv", read_rows)
    t2 = below(many, "contact_*.csv", read_rows)
    if t1.keys() != t2.keys():
        failures.append("%s: contact CSVs %s against %s" %
                        (name, sorted(t1), sorted(t2)))
    for path in t1:
        rows1, rows2 = t1[path], t2.get(path, [])
        if len(rows1) != len(rows2):
            failures.append("%s: %s has %d rows, one process %d" %
                            (name, path, len(rows2), len(rows1)))
            continue
        for column in (rows1[0].keys() if rows1 else []):
            if column in FLAGS or not all(number(r[column]) for r in rows1):
                changed = sum(r1[column] != r2[column]
                              for r1, r2 in zip(rows1, rows2))
                if changed:
                    failures.append("%s: %s: %d rows differ in %s" %
                                    (name, path, changed, column))
                continue
            values1 = [float(r[column]) for r in rows1]
            values2 = [float(r[column]) for r in rows2]
            scale = max(abs(v) for v in values1)
            if column in MOTIONS:
                scale = max(scale, u_scale)
            scale = scale or 1.0
            error = max(abs(x - y) for x, y in zip(values1, values2)) / scale
            worst = max(worst, error)
            if error > TOLERANCE:
                failures.append("%s: %s column %s differs by %.1e of its "
                                "largest" % (name, path, column, error))
    return worst


def scene_text(scene, solver, changes, folder):
    """The scene with absolute mesh paths, the solver path, the @p changes
    (pattern, replacement) made and its results written into @p folder."""
    text = open(os.path.join(SCENES_FOLDER, scene)).read()
    text = re.sub(r"(set File\s*=\s*)(\S+)",
                  lambda m: m.group(1) + os.path.normpath(
                      os.path.join(SCENES_FOLDER, m.group(2))), text)
    if solver:
        text = re.sub(r"\n\s*set Solver\s*=.*", "", text)
        text = text.replace("subsection Contact",
                            "subsection Contact\n  set Solver = %s" % solver,
                            1)
    for pattern, replacement in changes:
        text, n = re.subn(pattern, replacement, text)
        assert n == 1, (scene, pattern)
    if "subsection Output" not in text:
        text += "subsection Output\nend\n"
    return friction.with_output(text, folder)


def tight_krylov(text):
    """The iterative path's CG to 1e-14 of the load instead of 1e-12: the
    two runs may rebuild their AMG hierarchies at other iterations (each
    decides from the times it measures), so their solutions differ by what
    the tolerance leaves, amplified by the condition number: at 1e-12 the
    adaptive Hertz sphere's displacements differed by 1.2e-8 of max |u|
    once in CI (7.7e-10 in other runs)."""
    if not re.search(r"set Solver\s*=\s*iterative", text):
        return text
    text = re.sub(r"\n\s*set Krylov tolerance\s*=.*", "", text)
    return text.replace("subsection Contact", "subsection Contact\n"
                        "  set Krylov tolerance = 1e-14", 1)


def compare_runs(binary, folder, name, text, ranks, failures):
    """Run @p text by one process and by @p ranks; compare."""
    results = {}
    text = tight_krylov(text)
    for count in (0, ranks):
        out = os.path.join(folder, "%s_%d" % (name, count))
        scene = os.path.join(folder, "%s_%d.prm" % (name, count))
        with open(scene, "w") as f:
            f.write(text.replace("@FOLDER@", out))
        result = run(binary, scene, count)
        if result.returncode != 0:
            print(result.stdout[-3000:], result.stderr[-3000:])
            failures.append("%s on %d ranks: exit code %d" %
                            (name, max(count, 1), result.returncode))
            return
        results[count] = out
    one = below(results[0], "summary.json", read_json)
    many = below(results[ranks], "summary.json", read_json)
    worst = 0.0
    for path, summary in many.items():
        if summary["solver"].get("ranks") != ranks:
            failures.append("%s/%s: solver ranks %r, not %d" %
                            (name, path, summary["solver"].get("ranks"),
                             ranks))
        if bool(summary["solver"].get("distributed_mesh")) != \
                (name in DISTRIBUTED):
            failures.append("%s/%s: distributed mesh %r, expected %r" %
                            (name, path,
                             summary["solver"].get("distributed_mesh"),
                             name in DISTRIBUTED))
        # The sparse path on several ranks factorises with MUMPS over all
        # of them (Contact/Direct factor = automatic).
        if summary["solver"]["name"] == "sparse" and \
                summary["solver"].get("mumps_ranks") != ranks:
            failures.append("%s/%s: sparse path without MUMPS over %d "
                            "ranks (%r)" % (name, path, ranks,
                                            summary["solver"].get(
                                                "mumps_ranks")))
    if not one or one.keys() != many.keys():
        failures.append("%s: summaries %s against %s" % (name, sorted(one),
                                                         sorted(many)))
    for path in one:
        if path in many:
            worst = max(worst, worst_difference(name + "/" + path, one[path],
                                                many[path], failures))
    worst = max(worst, compare_fields(name, results[0], results[ranks],
                                      failures))
    paths = sorted({summary["solver"]["name"] +
                    (" on the distributed mesh"
                     if summary["solver"].get("distributed_mesh") else "")
                    for summary in many.values()})
    print("%s: %d ranks (%s) against one process: largest relative "
          "difference %.1e (tolerance %.0e)" % (name, ranks, ", ".join(paths),
                                                worst, TOLERANCE))


BLOCK = """subsection Mesh
  #                x0 y0 x1 y1 nx ny mat group left right bottom top
  set Source     = rectangles
  set Rectangles = 0, 0, 1, 0.5, 4, 2, 1, 0, 1, 1, 2, 3; \\
                   0.25, 0.5, 0.75, 0.75, 1, 1, 2, 1, 4, 4, 5, 6
end
%ssubsection Boundary conditions
  set Number of conditions = 3
  subsection Condition 0
    set Boundary ids = 2
    set Type         = displacement
  end
  subsection Condition 1
    set Boundary ids = 4
    set Type         = sliding
  end
  subsection Condition 2
    set Boundary ids = 6
    set Type         = traction
    set Value        = 0; -1e6
  end
end
subsection Contact
  set Solver = iterative
  set Number of interfaces = 1
  subsection Interface 0
    set Name               = block
    set Slave boundary id  = 5
    set Master boundary id = 3
  end
end
subsection Output
  set Folder   = @FOLDER@
  set Pictures = false
end
""" % friction.MATERIALS


def refused_once(binary, folder, name, text, expected, failures,
                 alone_says=None):
    """The scene @p text refused on 2 ranks as by one process: exit code 1,
    one error line printed once, holding @p expected (a string or a tuple
    of them), the one process's line; or, with @p alone_says, a line of
    its own, where one process's holds @p alone_says and not
    @p expected."""
    wanted = expected if isinstance(expected, tuple) else (expected,)
    scene = os.path.join(folder, re.sub(r"\W+", "_", name) + ".prm")
    with open(scene, "w") as f:
        f.write(text)
    alone = run(binary, scene, 0)
    result = run(binary, scene, 2)
    said = [line for line in result.stderr.splitlines()
            if line.startswith("knee_contact: error:")]
    print("%s on 2 ranks: exit code %d (one process %d), %d error line(s): "
          "%s" % (name, result.returncode, alone.returncode, len(said), said))
    as_alone = said and (said[0] in alone.stderr if alone_says is None else
                         alone_says in alone.stderr and
                         wanted[-1] not in alone.stderr)
    if result.returncode != 1 or alone.returncode != 1 or len(said) != 1 or \
            any(w not in said[0] for w in wanted) or not as_alone:
        failures.append("%s on 2 ranks: exit code %d, error lines %s" %
                        (name, result.returncode, said))


def main():
    binary = os.path.abspath(sys.argv[1])
    sanitize = len(sys.argv) > 2 and sys.argv[2] == "ON"
    failures = []
    with tempfile.TemporaryDirectory() as folder:
        for scene, solver, ranks, change in SCENES:
            if sanitize and scene in SANITIZER_SKIPS:
                print("%s: left out under the sanitizers" % scene)
                continue
            name = scene[:-4] + ("_" + solver if solver else "") + \
                ("_uniform" if any("Number of cycles" in c[1]
                                   for c in change) else "")
            compare_runs(binary, folder, name,
                         scene_text(scene, solver, change, "@FOLDER@"), ranks,
                         failures)
        compare_runs(binary, folder, "one_cell_block", BLOCK, 24, failures)
        # MUMPS with ranks that own no row of the matrix (38 dofs, 24
        # ranks hold 1 or 2 each, some none after the constraints).
        compare_runs(binary, folder, "one_cell_block_mumps",
                     BLOCK.replace("set Solver = iterative",
                                   "set Solver = sparse"), 24, failures)
        # Bodies moved along a frictional path (Load cases/Motion): the 3D
        # drag, hold, pull back and twist of drivers/motion.py on the
        # distributed iterative path (measured: 1e-15 of the energy). Left
        # out under the sanitizers: the moved cases' set-up is the code of
        # one process, the solves that of the 3D block above.
        if not sanitize:
            drag = motion.scene(3, "@FOLDER@").replace(
                "subsection Contact",
                "subsection Contact\n  set Solver = iterative", 1)
            compare_runs(binary, folder, "motion_drag_3d", drag, 2, failures)

        # Bad input: refused by every rank, said once.
        refused_once(binary, folder, "bad input",
                     BLOCK.replace("set Young's modulus = 3e9",
                                   "set Young's modulus = -3e9")
                     .replace("@FOLDER@", os.path.join(folder, "bad")),
                     "Young", failures)

        # A mesh refused where it may be distributed (the iterative path
        # on 2 ranks): rank 0 alone makes and checks it, the other takes
        # its refusal.
        refused_once(binary, folder, "a refused mesh",
                     BLOCK.replace("Slave boundary id  = 5",
                                   "Slave boundary id  = 1")
                     .replace("@FOLDER@", os.path.join(folder, "same")),
                     "both lie on body", failures)

        # A body no constraint holds, found on the distributed mesh: the
        # test of a free motion is collective there (each rank evaluates
        # the rows on its own dofs, RigidModes::free_motion()), and every
        # rank must name the same body and motion as one process.
        refused_once(binary, folder, "a body not held",
                     BLOCK.replace("set Boundary ids = 4\n"
                                   "    set Type         = sliding",
                                   "set Boundary ids = 4\n"
                                   "    set Type         = traction\n"
                                   "    set Value        = 0; 0")
                     .replace("@FOLDER@", os.path.join(folder, "free")),
                     "body 1 (block) is not held: its translation", failures)

        # A mesh too large for the machine where it may be distributed:
        # rank 0's check counts the distributed run (the ranks' shares,
        # rank 0's whole mesh) and refuses it in one line, said once; one
        # process refuses it with the whole run's estimate.
        large = scene_text("contact_patch_3d_hex.prm", "iterative",
                           [(r"(set Gmsh arguments.*)",
                             r"\1\n  set Global refinements = 12")],
                           os.path.join(folder, "large"))
        refused_once(binary, folder, "a mesh too large", large,
                     ("cells need about", "a rank on the distributed mesh"),
                     failures, alone_says="cells need about")

        # A .geo gmsh refuses: rank 0 alone meshes, the others take its
        # failure.
        geo = os.path.join(folder, "broken.geo")
        with open(geo, "w") as f:
            f.write("Point(1) = {0, 0, 0, 1};\nLine(1) = {1, 2};\n")
        with open(os.path.join(SCENES_FOLDER,
                               "contact_patch_3d_tet_iterative.prm")) as f:
            text = f.read()
        text = re.sub(r"set File\s*=.*", "set File = " + geo, text)
        text = re.sub(r"set Folder\s*=.*",
                      "set Folder = " + os.path.join(folder, "geo"), text)
        refused_once(binary, folder, "broken .geo", text, "gmsh failed",
                     failures)
    for failure in failures:
        print("FAIL " + failure)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
