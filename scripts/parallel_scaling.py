#!/usr/bin/python3
"""The same scene on 1, 2, 4, ... ranks: a table of times and memory.

Usage: parallel_scaling.py KNEE_CONTACT SCENE.prm [--ranks 1 2 4]
           [--repeat 3] [--solver iterative]

N = 1 runs as one process (no mpirun); N > 1 under mpirun (oversubscribed
where N exceeds the cores: the communication terms show, the speed-up
cannot). Each run writes its results into a folder of its own
(output/scaling/<scene>_<N>_<k>) and the table is read from its
summary.json: the whole run, the contact solve, the Krylov and AMG set-up
times of the iterative path, CG iterations, the peak resident memory of
rank 0 (every rank holds about the same) and the largest relative
difference of the contact forces and peak pressures from the one-process
run. Times are the median over --repeat runs; the ratios are of medians
measured in this one invocation (the machine is noisy).
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time


def run(binary, scene_text, folder, ranks):
    """One run; its summary.json and wall time."""
    os.makedirs(folder, exist_ok=True)
    scene = folder + ".prm"
    with open(scene, "w") as f:
        f.write(scene_text.replace("@FOLDER@", folder))
    command = [binary, scene]
    if ranks > 1:
        command = ["mpirun", "--oversubscribe", "-np", str(ranks)] + command
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    start = time.monotonic()
    result = subprocess.run(command, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)
    seconds = time.monotonic() - start
    if result.returncode != 0:
        sys.exit("%s on %d ranks failed (%d): %s" %
                 (scene, ranks, result.returncode, result.stderr[-2000:]))
    with open(os.path.join(folder, "summary.json")) as f:
        return json.load(f), seconds


def contact_numbers(summary):
    """Forces and peak pressures of every interface."""
    values = {}
    for name, interface in summary.get("contact_interfaces", {}).items():
        for key in ("force", "max_pressure"):
            values[name + "/" + key] = interface[key]
    return values


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary")
    parser.add_argument("scene")
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4])
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--solver", default=None,
                        help="Contact/Solver for every run (default: the "
                        "scene's)")
    args = parser.parse_args()
    binary = os.path.abspath(args.binary)
    scene = os.path.abspath(args.scene)
    text = open(scene).read()
    # Relative paths of the scene (meshes) from its folder.
    here = os.path.dirname(scene)
    text = re.sub(r"(set File\s*=\s*)(\S+)",
                  lambda m: m.group(1) + os.path.normpath(
                      os.path.join(here, m.group(2))), text)
    if args.solver:
        text = re.sub(r"\n\s*set Solver\s*=.*", "", text)
        text = text.replace("subsection Contact", "subsection Contact\n"
                            "  set Solver = %s" % args.solver, 1)
    text = re.sub(r"\n\s*set (Folder|Terminal|Write files|Pictures)\s*=.*",
                  "", text)
    if "subsection Output" not in text:
        text += "subsection Output\nend\n"
    text = text.replace("subsection Output", "subsection Output\n"
                        "  set Folder = @FOLDER@\n  set Pictures = false", 1)
    stem = os.path.splitext(os.path.basename(scene))[0]

    rows, reference = [], None
    for ranks in args.ranks:
        runs = [run(binary, text, os.path.abspath(os.path.join(
            "output", "scaling", "%s_%d_%d" % (stem, ranks, k))), ranks)
            for k in range(args.repeat)]
        summaries = [summary for summary, _ in runs]

        def median(read):
            return statistics.median(read(s) for s in summaries)

        numbers = contact_numbers(summaries[0])
        if reference is None:
            reference = numbers
        difference = max([abs(numbers[k] - reference[k]) / abs(reference[k])
                          for k in reference if reference[k]] + [0.0])
        rows.append({
            "ranks": ranks,
            "dofs": summaries[0]["n_dofs"],
            "path": summaries[0]["solver"].get("name", "-"),
            "run": statistics.median(seconds for _, seconds in runs),
            "solve": median(lambda s: s["wall_time"].get("solve", 0)),
            "krylov": median(lambda s: s["solver"].get("krylov_time", 0)),
            "amg": median(lambda s: s["solver"].get("amg_setup", 0)),
            "cg": median(lambda s: s["solver"].get("krylov_iterations", 0)),
            "estimate": median(
                lambda s: s["solver"].get("estimated_iterative_MB", 0)),
            "measured": median(
                lambda s: s["solver"].get("iterative_memory_MB", 0)),
            "peak": median(lambda s: s["solver"].get("peak_memory_MB", 0)),
            "difference": difference})

    print("| ranks | DoFs | path | whole run [s] | solve [s] | Krylov [s] "
          "| AMG set-up [s] | CG it. | speed-up (run / solve) "
          "| path estimate / measured per rank [MB] | peak per rank [MB] "
          "| forces, peaks vs N=1 |")
    print("|" + "---|" * 12)
    base = rows[0]
    for row in rows:
        print("| %d | %d | %s | %.1f | %.1f | %.1f | %.2f | %d | %.2f / %.2f "
              "| %.0f / %.0f | %.0f | %.1e |" % (
                  row["ranks"], row["dofs"], row["path"], row["run"],
                  row["solve"], row["krylov"], row["amg"], row["cg"],
                  base["run"] / row["run"],
                  base["solve"] / max(row["solve"], 1e-9), row["estimate"],
                  row["measured"], row["peak"], row["difference"]))


if __name__ == "__main__":
    main()
