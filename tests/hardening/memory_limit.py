#!/usr/bin/env python3
"""The solver's memory estimate under an address-space limit (ulimit -v).

The sagittal knee (prm/knee.prm) refined adaptively for 6 cycles with
Contact/Solver = condensed: on the last mesh (78 206 dofs, k = 4 754 contact
unknowns) the condensed path's dense arrays need several times the sparse
path's factor. A first run without a limit gives both estimates and the
process's mapped size when the path is chosen (summary.json). Then:

1. limit = mapped size + the mean of the two needs / 0.8 (the head room the
   program keeps): the condensed path does not fit, the sparse one does;
   the run must switch to it, say so in one line, exit 0 with every check
   passing, and give the same results as the unlimited run (to 1e-10);
2. limits from mapped size + 0.9 x the sparse path's need down in 20 MB
   steps: each run succeeds or exits 1 with one out-of-memory line and no
   result folder, and one of them must be the estimate's one-line refusal
   naming the needs and the limit;
3. the 3D Hertz sphere (prm/hertz_sphere_3d.prm, h_contact 0.014, 20 820
   dofs) with Contact/Solver = sparse, where the sparse factor needs about
   seven times the iterative path (CG with AMG, memory linear in the dofs):
   limits from its mapped size + the sparse need / 0.8 + 100 MB down in
   25 MB steps until a run takes the iterative path; it must say so in one
   line, exit 0, give the unlimited run's energy to the iterative path's
   tolerance (tests/unit/solver_paths.cc: 1e-8 relative at this contrast of
   2), and its memory estimate must be within 2x of the resident memory it
   added by its first solve; the runs before it finish on the sparse path
   or are refused in one out-of-memory line (the mesh's early estimate is
   cruder than the solver's).

Every run gets a TMPDIR of its own, which must be empty at the end: the
limited runs leave by std::_Exit, which skips the exit handlers (the
iterative path's MPI session folder used to stay behind).

Skipped (77) under AddressSanitizer, which reserves terabytes of address
space at start.
"""

import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile

program, root = sys.argv[1], sys.argv[2]
if len(sys.argv) > 3 and sys.argv[3] == "ON":
    print("SKIP: address-space limits do not apply under AddressSanitizer")
    sys.exit(77)

work = tempfile.mkdtemp(prefix="memory_limit-")
try:
    shutil.copy(os.path.join(root, "prm", "knee.geo"), work)
    tmpdir = os.path.join(work, "tmp")
    os.mkdir(tmpdir)
    scene = open(os.path.join(root, "prm", "knee.prm")).read()
    scene += """
subsection Refinement
  set Strategy = adaptive
  set Refine fraction = 0.3
  set Number of adaptive cycles = 6
end
subsection Contact
  set Solver = condensed
end
subsection Output
  set Pictures = false
  set Folder = %s
end
"""

    def run(name, limit_kb=None):
        folder = os.path.join(work, name)
        path = os.path.join(work, name + ".prm")
        with open(path, "w") as f:
            f.write(scene % folder)

        def limit():
            if limit_kb is not None:
                resource.setrlimit(resource.RLIMIT_AS,
                                   (limit_kb * 1024, limit_kb * 1024))
        # One malloc arena: glibc reserves 64 MB of address space per
        # thread arena, and fewer when a limit is set, which would make
        # the mapped size of the limited runs differ from the first run's.
        # A TMPDIR of its own: a run that leaves by std::_Exit (out of
        # memory, or any run under a limit) skips the exit handlers and
        # must still leave nothing there (the iterative path's MPI
        # session folder).
        env = dict(os.environ, MALLOC_ARENA_MAX="1", TMPDIR=tmpdir)
        done = subprocess.run([program, path], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True,
                              preexec_fn=limit, env=env)
        summary = os.path.join(folder, "summary.json")
        return (done.returncode, done.stdout,
                json.load(open(summary)) if os.path.exists(summary) else None)

    def unlimited(name, other):
        """A run without a limit: its summary, mapped size at the choice,
        and the sparse and the @p other path's estimates."""
        code, log, free = run(name)
        if code != 0 or free is None:
            sys.exit("FAIL: the unlimited run %s failed (exit %d):\n%s" %
                     (name, code, log[-2000:]))
        solver = free["solver"]
        mapped = solver["process_virtual_MB"]
        sparse = solver["estimated_sparse_MB"]
        estimate = solver["estimated_%s_MB" % other]
        print("%s: path %s, estimates sparse %.0f MB, %s %.0f MB, mapped "
              "%.0f MB" % (name, solver["name"], sparse, other, estimate,
                           mapped))
        return free, solver, mapped, sparse, estimate

    free, solver, mapped, sparse, condensed = unlimited("unlimited",
                                                        "condensed")
    if solver["name"] != "condensed" or not condensed > 2 * sparse:
        sys.exit("FAIL: the scene no longer makes the condensed path the "
                 "dearer one by 2x; choose a larger one")

    ok = True
    limit = int((mapped + (sparse + condensed) / 2 / 0.8) * 1024)
    code, log, limited = run("switch", limit)
    switched = [line for line in log.splitlines()
                if "solver: sparse (Contact/Solver = condensed needs about"
                in line]
    same = False
    if code == 0 and limited is not None:
        energy = (free.get("energy"), limited.get("energy"))
        # The tolerance of tests/unit/solver_paths.cc for a Young's modulus
        # contrast r: 1e-12 r (r = 4e11 / 3.4e8 = 1 176 here).
        same = (energy[0] is not None and
                abs(energy[0] - energy[1]) <= 1.2e-9 * abs(energy[0]))
    if limited:
        print("  energy %.12g / %.12g, mapped %.0f, available %.0f" % (
            free["energy"], limited["energy"],
            limited["solver"]["process_virtual_MB"],
            limited["solver"]["available_MB"]))
    print("limit %d MB: exit %d, switch line %s, path %s, energy %s" %
          (limit // 1024, code, "found" if switched else "MISSING",
           limited["solver"]["name"] if limited else "-",
           "same" if same else "DIFFERENT"))
    ok = ok and code == 0 and bool(switched) and same and \
        limited["solver"]["name"] == "sparse"

    # The mapped size at the choice is not the same under every limit
    # (libraries reserve less address space when less is left: measured
    # 1 072 MB unlimited, 895 MB under a 1 132 MB limit), so the refusal is
    # sought on a descending series of limits, 20 MB apart, from the first
    # run's mapped size + 0.9 x the sparse need: every run must either
    # succeed or end with exit 1 and one line saying out of memory (the
    # estimate's refusal, or an allocation refused earlier in the run),
    # never a crash, a kill or a half-written result folder, and the
    # estimate's refusal must come before the series ends.
    refusal = None
    for step in range(24):
        limit = int((mapped + 0.9 * sparse - 20 * step) * 1024)
        code, log, refused = run("refuse", limit)
        lines = [line for line in log.splitlines()
                 if line.startswith("knee_contact: error: out of memory")]
        left = os.path.exists(os.path.join(work, "refuse"))
        estimate = [line for line in lines
                    if line.startswith("knee_contact: error: out of memory: "
                                       "the contact solve")]
        print("limit %d MB: exit %d, %s" % (
            limit // 1024, code,
            "the estimate's refusal" if estimate else
            "out of memory earlier" if lines else "finished"))
        if code == 0:
            shutil.rmtree(os.path.join(work, "refuse"), ignore_errors=True)
            continue
        if code != 1 or len(lines) != 1 or left:
            print("FAIL: exit %d, %d out-of-memory lines, result folder %s:\n%s"
                  % (code, len(lines), "left" if left else "none",
                     log[-1000:]))
            ok = False
            break
        if estimate:
            refusal = estimate[0]
            break
    if refusal is None:
        ok = False
        print("FAIL: no run was refused by the estimate")
    else:
        print(refusal[:150] + " ...")

    # 3. The switch to the iterative path.
    for name in ("hertz_sphere_3d.geo", "hertz_sphere_3d.prm"):
        shutil.copy(os.path.join(root, "prm", name), work)
    scene = open(os.path.join(work, "hertz_sphere_3d.prm")).read().replace(
        "h_contact 0.01", "h_contact 0.014")
    scene += """
subsection Contact
  set Solver = sparse
end
subsection Output
  set Pictures = false
  set Folder = %s
end
"""
    free, solver, mapped, sparse, iterative = unlimited("sphere",
                                                        "iterative")
    switched = False
    for step in range(12):
        limit = int((mapped + sparse / 0.8 + 100 - 25 * step) * 1024)
        code, log, limited = run("sphere_limited", limit)
        line = [l for l in log.splitlines()
                if "solver: iterative (the sparse path needs about" in l]
        errors = [l for l in log.splitlines()
                  if l.startswith("knee_contact: error: ")]
        path = limited["solver"]["name"] if limited else "-"
        print("limit %d MB: exit %d, path %s%s" % (
            limit // 1024, code, path,
            (", " + errors[0][21:120]) if errors else ""))
        left = os.path.exists(os.path.join(work, "sphere_limited"))
        shutil.rmtree(os.path.join(work, "sphere_limited"), ignore_errors=True)
        if code == 1 and len(errors) == 1 and "out of memory" in errors[0] \
                and not left:
            continue
        if code != 0 or path == "-":
            print("FAIL: the run neither finished nor was refused in one "
                  "line:\n" + log[-1000:])
            ok = False
            break
        if path == "iterative":
            same = abs(limited["energy"] - free["energy"]) <= \
                1e-8 * abs(free["energy"])
            # The path's estimate against the resident memory it added by
            # its first solve: within 2x either way.
            estimate = limited["solver"]["estimated_iterative_MB"]
            measured = limited["solver"]["iterative_memory_MB"]
            close = 0.5 <= measured / estimate <= 2
            print("  iterative path: estimated %.1f MB, measured %.1f MB: %s"
                  % (estimate, measured, "within 2x" if close else "NOT"))
            ok = ok and close
            print("  %s; energy %.12g / %.12g: %s" % (
                line[0].strip()[:110] if line else "NO SWITCH LINE",
                free["energy"], limited["energy"],
                "same" if same else "DIFFERENT"))
            ok = ok and bool(line) and same
            switched = True
            break
    if not switched:
        ok = False
        print("FAIL: no run switched to the iterative path")
    left = os.listdir(tmpdir)
    print("left in TMPDIR by the runs: %s" % (left or "nothing"))
    ok = ok and not left
    print("PASS" if ok else "FAIL")
    sys.exit(0 if ok else 1)
finally:
    shutil.rmtree(work, ignore_errors=True)
