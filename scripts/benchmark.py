#!/usr/bin/env python3
"""Speed of the contact solve against one linear solve, per mesh size.

    python3 scripts/benchmark.py build/knee_contact [--max-dofs 1.8e6]
        [--step41-max-dofs 5e5] [--repeat 1]
        [--scenes hertz,knee,adaptive,gait] [--solver automatic]

For every scene (Hertz, prm/hertz.prm with lc_fine 0.02, lc_coarse 0.1; the
sagittal knee, prm/knee.prm) and every number of global refinements up to
--max-dofs, knee_contact runs the scene with Contact/Solver = --solver
(default automatic; the table says which path it took) and
Contact/Reference solve = true, so that one run gives both numbers of the
ratio: the whole contact solve (ordering, factorisation, Schur complement,
active-set loop, expansion) and one linear solve of the same mesh with the
final active set held fixed (CHOLMOD with the same METIS vertex ordering:
condensation of the constraints, ordering, factorisation, solve). Up to
--step41-max-dofs the first version's path (Contact/Solver = step-41: UMFPACK
in every iteration) runs too: before and after. With --repeat N each run is
repeated and every figure is the median.

Printed: one table per scene (times in seconds, memory = peak resident set
of the run per dof) and the exponent b of a least-squares fit time = a n^b
over the sizes >= 1e4 dofs. Pictures are off; output is the VTU and CSVs.

Scene "adaptive" refines the knees adaptively (ADAPTIVE below) past 4e5
dofs and prints per cycle the path taken, the contact solve against one
linear solve of the same cycle, iterations and memory (from study.csv).

Scenes "hertz3d" (prm/hertz_sphere_3d.prm) and "knee3d" (prm/knee_3d.prm)
are 3D: tetrahedra of gmsh, so each size is a new mesh of the .geo
(h_contact divided by sqrt 2 a step, about 2.8 times the dofs) instead of a
global refinement; the same table.

Scenes "knee3d-amg" and "hertz3d-amg" measure the iterative path (CG with
ML's AMG, Contact/Solver = iterative) on the 3D knee (h_contact 1.2) and the
3D Hertz sphere (h_contact 0.01) at 0, 1, 2, ... global refinements of the
tetrahedra (8 times the cells a step) up to --max-dofs: per size the
active-set iterations, CG iterations per solve (mean and largest), AMG
set-ups and their time, the contact solve, one linear solve by the same path
(a new hierarchy, CG from zero to the final tolerance), their ratio, the
peak memory per dof; and up to --direct-max-dofs the automatic choice among
the direct paths (condensed or sparse) on the same mesh: the crossover.
Scene "hertz-amg" is the same table in 2D (prm/hertz.prm as in "hertz",
quadrilaterals, 4 times the cells a step).

Scene "gait" (prm/knee_gait.prm with 11 load cases t = 0:0.1:1) measures
load cases: per size the first case (assembly and contact solve), the
median further case (load vector assembly, condensation, active-set loop
from the previous case's set, back substitution: solve_time of
load_cases.csv), their ratio, the median iterations of the further cases,
and the output (VTU, CSVs, summary) per case.
"""

import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SCENES = {
    "hertz": ("prm/hertz.prm",
              {(("Mesh",), "Gmsh arguments"):
               "-setnumber lc_fine 0.02 -setnumber lc_coarse 0.1"}),
    "knee": ("prm/knee.prm", {}),
    "hertz3d": ("prm/hertz_sphere_3d.prm", {}),
    "knee3d": ("prm/knee_3d.prm", {}),
    "gait": ("prm/knee_gait.prm", {(("Load cases",), "Values of t"):
                                   "0:0.1:1"}),
}

# The 3D scenes' sizes: gmsh arguments per size (tetrahedra are meshed anew,
# not refined).
SIZES_3D = {
    "hertz3d": ["-setnumber h_contact %g" % h
                for h in (0.04, 0.028, 0.02, 0.014, 0.01, 0.007, 0.005)],
    "knee3d": ["-setnumber h_contact %g -setnumber h_far %g" % (h, 5 * h)
               for h in (2.4, 1.7, 1.2, 0.85, 0.6, 0.42)],
}

# The adaptive series (--scenes adaptive): both knees refined adaptively
# (Kelly + contact zone, refine fraction 0.3) until a cycle passes 4e5 dofs.
# "knee-issue20" is the variant of the sagittal knee the solver issue was
# measured on (chirulen E = 6e8, load 0.3e7: a longer contact zone).
ADAPTIVE = {
    "knee-issue20": ("prm/knee.prm", 9, {
        (("Materials", "Material 2"), "Young's modulus"): "6e8",
        (("Boundary conditions", "Condition 1"), "Value"): "0.3e7"}),
    "knee": ("prm/knee.prm", 9, {}),
    "knee_frontal": ("prm/knee_frontal.prm", 9, {}),
}


def set_entries(text, scene_dir, changes):
    """The scene with each (subsection path, name) of changes set; entries
    that are absent are added to their subsection (created if needed), and
    Mesh/File is made absolute."""
    lines = text.splitlines()
    path, done, out = [], set(), []
    for line in lines:
        words = line.split()
        if words[:1] == ["subsection"]:
            path.append(line.split(None, 1)[1].strip())
        elif words[:1] == ["end"]:
            # Add what belongs to this subsection and is not there yet.
            for (where, name), value in changes.items():
                if "/".join(where) == "/".join(path) and \
                        (where, name) not in done:
                    out.append("  set %s = %s" % (name, value))
                    done.add((where, name))
            path.pop()
        elif words[:1] == ["set"]:
            name, value = line.split(None, 1)[1].split("=", 1)
            key = (tuple(path), name.strip())
            if key in changes:
                line = "  set %s = %s" % (name.strip(), changes[key])
                done.add(key)
            elif key == (("Mesh",), "File") and value.strip() and \
                    not os.path.isabs(value.strip()):
                line = "  set File = " + os.path.join(scene_dir, value.strip())
        out.append(line)
    for (where, name), value in changes.items():
        if (where, name) not in done:
            out += ["subsection " + w for w in where]
            out.append("  set %s = %s" % (name, value))
            out += ["end"] * len(where)
            done.add((where, name))
    return "\n".join(out) + "\n"


def run(program, scene, changes, work, result="summary.json"):
    scene_path = os.path.join(ROOT, scene)
    changes = dict(changes)
    folder = os.path.join(work, "out")
    changes[("Output",), "Folder"] = folder
    changes[("Output",), "Pictures"] = "false"
    text = set_entries(open(scene_path).read(), os.path.dirname(scene_path),
                       changes)
    path = os.path.join(work, "scene.prm")
    with open(path, "w") as f:
        f.write(text)
    done = subprocess.run([program, path], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True)
    if done.returncode != 0:
        sys.exit("benchmark: %s failed (exit %d):\n%s" %
                 (scene, done.returncode, done.stdout[-2000:]))
    if result.endswith(".csv"):
        with open(os.path.join(folder, result)) as f:
            rows = list(csv.DictReader(f))
        return rows, json.load(open(os.path.join(
            folder, "case_%03d" % (len(rows) - 1), "summary.json")))
    return json.load(open(os.path.join(folder, result)))


def gait_benchmark(program, args):
    scene, base = SCENES["gait"]
    print("\ngait (%s, t = 0:0.1:1)" % scene)
    print("| dofs | first case [s] | further case [s] | ratio | "
          "further iterations | output per case [s] |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="benchmark-") as work:
        for level in range(10):
            changes = dict(base)
            changes[("Mesh",), "Global refinements"] = str(level)
            cases, last = run(program, scene, changes, work,
                              "load_cases.csv")
            wall = last["wall_time"]
            first = wall.get("assembly", 0) + float(cases[0]["solve_time"])
            further = statistics.median(float(c["solve_time"])
                                        for c in cases[1:])
            iterations = statistics.median(int(c["iterations"])
                                           for c in cases[1:])
            print("| %d | %.3g | %.3g | %.3f | %g | %.3g |" % (
                last["n_dofs"], first, further, further / first, iterations,
                wall.get("output", 0) / len(cases)), flush=True)
            if 4 * last["n_dofs"] > args.max_dofs:
                break


def adaptive_benchmark(program, args):
    """Per cycle of an adaptive run: dofs, contact rows (pairs), contact
    unknowns k, the path the automatic choice took, the contact solve and
    one linear solve with the final active set (same run), their ratio,
    active-set iterations and the peak memory so far; then the whole run's
    wall time."""
    for name, (scene, cycles, base) in ADAPTIVE.items():
        changes = dict(base)
        changes[("Refinement",), "Strategy"] = "adaptive"
        changes[("Refinement",), "Refine fraction"] = "0.3"
        changes[("Refinement",), "Number of adaptive cycles"] = str(cycles)
        changes[("Contact",), "Solver"] = args.solver
        changes[("Contact",), "Reference solve"] = "true"
        with tempfile.TemporaryDirectory(prefix="benchmark-") as work:
            runs = []
            for _ in range(args.repeat):
                clock = time.time()
                summary = run(program, scene, changes, work)
                wall = time.time() - clock
                with open(os.path.join(work, "out", "study.csv")) as f:
                    runs.append((wall, list(csv.DictReader(f)), summary))
        rows = runs[0][1]
        print("\nadaptive %s (%s, Solver = %s), median of %d run(s): "
              "whole run %.3g s" % (name, scene, args.solver, args.repeat,
                                    statistics.median(r[0] for r in runs)))
        print("| cycle | dofs | rows | k | path | it | contact [s] | "
              "one solve [s] | ratio | peak memory [MB] | kB/dof |")
        print("|---|---|---|---|---|---|---|---|---|---|---|")
        for i, r in enumerate(rows):
            def median(column):
                return statistics.median(float(run[1][i][column])
                                         for run in runs)
            contact, reference = (median("contact_solve"),
                                  median("reference_solve"))
            print("| %s | %s | %s | %d | %s | %s | %.3g | %.3g | %.2f | "
                  "%.0f | %.2f |" % (
                      r["cycle"], r["dofs"], r["pairs"],
                      float(r["contact_unknowns"]), r["solver"],
                      r["iterations"], contact, reference,
                      contact / reference if reference > 0 else float("nan"),
                      median("peak_memory_MB"),
                      median("peak_memory_MB") * 1024 / float(r["dofs"])),
                  flush=True)


AMG_SCENES = {
    "knee3d-amg": ("prm/knee_3d.prm", {}),
    "hertz3d-amg": ("prm/hertz_sphere_3d.prm", {}),
    "hertz-amg": SCENES["hertz"],
}


def amg_benchmark(program, name, args):
    """The iterative path per global refinement, and the direct paths on
    the same meshes while they are below --direct-max-dofs."""
    scene, base = AMG_SCENES[name]
    rows = []
    with tempfile.TemporaryDirectory(prefix="benchmark-") as work:
        for level in range(6):
            changes = dict(base)
            changes[("Mesh",), "Global refinements"] = str(level)
            changes[("Contact",), "Solver"] = "iterative"
            changes[("Contact",), "Reference solve"] = "true"
            changes[("Contact",), "Coarse start levels"] = str(
                args.coarse_start)
            r = run(program, scene, changes, work)
            solver = r["solver"]
            row = {
                "dofs": r["n_dofs"], "pairs": r["n_contact_pairs"],
                "it": r["active_set_iterations"],
                "cg": solver["krylov_iterations"] /
                max(solver["krylov_solves"], 1),
                "cg_max": solver["krylov_iterations_max"],
                "cg_one": solver.get("reference_krylov_iterations", 0),
                "setups": solver["amg_setups"],
                "setup": solver["amg_setup"],
                "contact": solver["contact_solve"],
                "coarse": solver.get("coarse_start", 0),
                "one": solver.get("reference_solve", float("nan")),
                "memory": solver["peak_memory_MB"],
                "estimate": solver.get("estimated_iterative_MB", 0),
                "measured": solver.get("iterative_memory_MB", 0),
                "mesh": r["wall_time"].get("mesh", 0),
                "output": r["wall_time"].get("output: vtu", 0),
                "total": sum(r["wall_time"].values()),
                "direct": float("nan"), "direct_path": "-",
                "direct_memory": float("nan"),
            }
            if row["dofs"] <= args.direct_max_dofs:
                changes[("Contact",), "Solver"] = "automatic"
                changes[("Contact",), "Reference solve"] = "false"
                # The automatic choice among the direct paths only: the
                # scene asks for the cheaper direct one.
                direct = []
                for path in ("condensed", "sparse"):
                    changes[("Contact",), "Solver"] = path
                    direct.append(run(program, scene, changes, work))
                d, s = direct
                best = min((d, s), key=lambda x: x["solver"]["contact_solve"])
                row["direct"] = best["solver"]["contact_solve"]
                row["direct_path"] = best["solver"]["name"]
                row["direct_memory"] = best["solver"]["peak_memory_MB"]
            rows.append(row)
            print("%s: %d dofs done" % (name, row["dofs"]), file=sys.stderr,
                  flush=True)
            # The next refinement's size: 2^dim times the dofs.
            if 2 ** r["dimension"] * row["dofs"] > args.max_dofs:
                break
    print("\n%s (%s), Contact/Solver = iterative" % (name, scene))
    header = ("dofs", "pairs", "it", "CG/solve", "CG max", "CG one",
              "AMG set-ups", "set-up", "contact", "coarse start",
              "one solve", "ratio",
              "kB/dof", "estimate MB", "measured MB", "mesh", "VTU",
              "run", "direct (faster path)", "direct kB/dof",
              "direct/iterative")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for r in rows:
        # The ratio counts the coarse start's time as the contact solve's.
        print("| %d | %d | %d | %.0f | %d | %d | %d | %.3g | %.3g | %.3g | "
              "%.3g | %.2f | %.2f | %.0f | %.0f | %.3g | %.3g | %.3g | %s | "
              "%s | %s |" % (
                  r["dofs"], r["pairs"], r["it"], r["cg"], r["cg_max"],
                  r["cg_one"], r["setups"], r["setup"], r["contact"],
                  r["coarse"], r["one"], (r["contact"] + r["coarse"]) /
                  r["one"],
                  r["memory"] * 1024 / r["dofs"], r["estimate"],
                  r["measured"], r["mesh"], r["output"], r["total"],
                  "-" if math.isnan(r["direct"]) else
                  "%.3g (%s)" % (r["direct"], r["direct_path"]),
                  "-" if math.isnan(r["direct"]) else
                  "%.2f" % (r["direct_memory"] * 1024 / r["dofs"]),
                  "-" if math.isnan(r["direct"]) else
                  "%.2f" % (r["direct"] / r["contact"])))
    sizes = [r["dofs"] for r in rows]
    print("fitted exponent (time ~ dofs^b): contact solve %.2f, one solve "
          "%.2f" % (exponent(sizes, [r["contact"] for r in rows]),
                    exponent(sizes, [r["one"] for r in rows])))


def median_run(program, scene, changes, work, repeat):
    runs = [run(program, scene, changes, work) for _ in range(repeat)]

    def median(get):
        return statistics.median(get(r) for r in runs)
    first = runs[0]
    solver = first["solver"]
    figures = {
        "dofs": first["n_dofs"],
        "pairs": first["n_contact_pairs"],
        "iterations": first["active_set_iterations"],
        "k": solver.get("contact_unknowns", 0),
        "path": solver.get("name", "?"),
        "contact": median(lambda r: r["solver"]["contact_solve"]),
        "reference": median(lambda r: r["solver"].get("reference_solve", 0)),
        "difference": max(r["solver"].get("reference_difference", 0)
                          for r in runs),
        "memory": median(lambda r: r["solver"]["peak_memory_MB"]),
    }
    figures["choice"] = median(lambda r: r["solver"].get("choice_ordering", 0)
                               + r["solver"].get("choice_analysis", 0))
    for phase in ["ordering", "factorisation", "schur_complement",
                  "loop_setup", "active_set_loop", "expansion",
                  "factor_memory_MB", "dense_memory_MB"]:
        figures[phase] = median(lambda r: r["solver"].get(phase, 0))
    for phase in ["setup", "assembly", "output"]:
        figures[phase] = median(lambda r: r["wall_time"].get(phase, 0))
    return figures


def exponent(sizes, times):
    points = [(math.log(n), math.log(t)) for n, t in zip(sizes, times)
              if n >= 1e4 and t > 0]
    if len(points) < 2:
        return float("nan")
    mx = sum(p[0] for p in points) / len(points)
    my = sum(p[1] for p in points) / len(points)
    return sum((x - mx) * (y - my) for x, y in points) / \
        sum((x - mx) ** 2 for x, _ in points)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("program")
    parser.add_argument("--max-dofs", type=float, default=1.8e6)
    parser.add_argument("--step41-max-dofs", type=float, default=5e5)
    parser.add_argument("--direct-max-dofs", type=float, default=3e5,
                        help="largest mesh of the direct paths in the "
                        "knee3d-amg and hertz3d-amg series")
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--coarse-start", type=int, default=0,
                        help="Contact/Coarse start levels of the "
                        "knee3d-amg, hertz3d-amg and hertz-amg series")
    parser.add_argument("--scenes", default="hertz,knee,adaptive")
    parser.add_argument("--solver", default="automatic",
                        help="Contact/Solver of the runs (automatic, "
                        "condensed, sparse)")
    args = parser.parse_args()
    program = os.path.abspath(args.program)

    for name in args.scenes.split(","):
        if name == "gait":
            gait_benchmark(program, args)
            continue
        if name == "adaptive":
            adaptive_benchmark(program, args)
            continue
        if name in AMG_SCENES:
            amg_benchmark(program, name, args)
            continue
        scene, base = SCENES[name]
        rows = []
        with tempfile.TemporaryDirectory(prefix="benchmark-") as work:
            levels = SIZES_3D.get(name, range(10))
            for level in levels:
                changes = dict(base)
                if name in SIZES_3D:
                    changes[("Mesh",), "Gmsh arguments"] = level
                else:
                    changes[("Mesh",), "Global refinements"] = str(level)
                changes[("Contact",), "Solver"] = args.solver
                changes[("Contact",), "Reference solve"] = "true"
                row = median_run(program, scene, changes, work, args.repeat)
                row["step41"] = float("nan")
                if row["dofs"] <= args.step41_max_dofs:
                    changes[("Contact",), "Solver"] = "step-41"
                    changes[("Contact",), "Reference solve"] = "false"
                    old = median_run(program, scene, changes, work,
                                     args.repeat)
                    row["step41"] = old["contact"]
                    row["step41_iterations"] = old["iterations"]
                rows.append(row)
                print("%s: %d dofs done" % (name, row["dofs"]),
                      file=sys.stderr, flush=True)
                growth = 2.83 if name in SIZES_3D else 4
                if growth * row["dofs"] > args.max_dofs:
                    break

        print("\n%s (%s), median of %d run(s)" % (name, scene, args.repeat))
        header = ("dofs", "pairs", "k", "path", "it", "one solve", "contact",
                  "ratio", "step-41", "speed-up", "choice", "order", "factor",
                  "Schur",
                  "loop set-up", "loop", "expand", "setup", "assembly",
                  "output", "kB/dof", "factor kB/dof", "dense kB/dof")
        print("| " + " | ".join(header) + " |")
        print("|" + "---|" * len(header))
        for r in rows:
            print("| %d | %d | %d | %s | %d | %.3g | %.3g | %.2f | %.3g | %.1f | "
                  "%.3g | %.3g | %.3g | %.3g | %.3g | %.3g | %.3g | %.3g | %.3g | "
                  "%.3g | %.2f | %.2f | %.2f |" % (
                      r["dofs"], r["pairs"], r["k"], r["path"],
                      r["iterations"],
                      r["reference"], r["contact"],
                      r["contact"] / r["reference"], r["step41"],
                      r["step41"] / r["contact"], r["choice"], r["ordering"],
                      r["factorisation"], r["schur_complement"],
                      r["loop_setup"], r["active_set_loop"], r["expansion"],
                      r["setup"], r["assembly"], r["output"],
                      r["memory"] * 1024 / r["dofs"],
                      r["factor_memory_MB"] * 1024 / r["dofs"],
                      r["dense_memory_MB"] * 1024 / r["dofs"]))
        sizes = [r["dofs"] for r in rows]
        print("fitted exponent (time ~ dofs^b, sizes >= 1e4): contact solve "
              "%.2f, one solve %.2f, step-41 %.2f" % (
                  exponent(sizes, [r["contact"] for r in rows]),
                  exponent(sizes, [r["reference"] for r in rows]),
                  exponent([r["dofs"] for r in rows
                            if not math.isnan(r["step41"])],
                           [r["step41"] for r in rows
                            if not math.isnan(r["step41"])])))
        print("largest difference of the contact solution from the "
              "reference solve (relative, max norm): %.1e" %
              max(r["difference"] for r in rows))


if __name__ == "__main__":
    main()
