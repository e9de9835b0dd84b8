#!/usr/bin/python3
"""The error bars (Refinement: estimate_errors) against true errors.

Each scene runs its own mesh sequence; per cycle, study.csv gives the peak
contact pressure and the energy a(u,u) with their estimated relative
errors (the error bars the run reports, from the cycles up to that one),
and the true error is the distance to a reference computed independently
of the estimator:
  - tests/accuracy/knee.prm (sagittal knee, 5 adaptive cycles): overkill
    solution 453 698 dofs, peak 8.460989 MPa, a(u,u) = 9.469803 J/m, both
    known to about 5e-5 (README, "Speed against error");
  - tests/accuracy/knee_frontal.prm (5 adaptive cycles): overkill 708 930
    dofs, peak 7.4985 MPa (to about 3e-4), a(u,u) = 7.0609 J/m (2e-4);
  - tests/accuracy/two_rings.prm (6 global cycles): Lame's solution,
    contact pressure 16 851 364.2545 Pa, a(u,u) = the internal pressure's
    work p_i u_r(a) pi a / 2 (exact).
Asserted for the energy (its bar: strain recovery on each mesh), over the
(scene, cycle) pairs after the first two cycles, as issue 24 asks:
  (1) the true error lies within the bar in at least 90 %;
  (2) the bar is at most 5 times the true error in at least 90 % of the
      pairs whose true error is above 3 times the reference's own
      uncertainty (below it the true error is not known well enough to
      judge a bar by);
and every bar of both quantities is finite from the second cycle on. The
peak pressure's bars (from the mesh sequence) are reported beside them,
not asserted: on the adaptive knees they are 0.15 to 19 times the true
error (issue 24 stays open for them).
Target mode (Refinement/Target error): the two rings (global) to 2 % in the
peak pressure and 1e-4 in the energy, the sagittal knee (adaptive) to
0.5 % and 5e-4: each run must stop with its bar below the target, and its
true error must be below the target too.
Usage: error_bars.py KNEE_CONTACT [SCENE_DIR]
"""
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ACCURACY = os.path.normpath(os.path.join(HERE, "..", "accuracy"))

# Inner ring of two_rings.prm: u_r = A r + B / r, at r = a = 1.
RING_U_A = 0.00012913561528890945 + 0.0009728390382222736
SCENES = [
    ("knee.prm", {"peak": (8.460989e6, 5e-5), "energy": (9.469803, 5e-5)}),
    ("knee_frontal.prm", {"peak": (7.4985e6, 3e-4),
                          "energy": (7.0609, 2e-4)}),
    ("two_rings.prm", {"peak": (16851364.254506525, 1e-12),
                       "energy": (1e8 * RING_U_A * math.pi / 2, 1e-12)}),
]


def run(binary, scene, folder, refinement=None, name=None):
    """The scene with an absolute mesh path, its output in folder (as
    name), with the Refinement entries of @p refinement (a dict) in place
    of its own; the rows of its study.csv and the run's summary.json."""
    with open(scene) as f:
        text = f.read()
    base = os.path.dirname(scene)

    def absolute(match):
        value = match.group(2).strip()
        if value and not os.path.isabs(value):
            value = os.path.normpath(os.path.join(base, value))
        return match.group(1) + value

    text = re.sub(r"^(\s*set\s+File\s*=\s*)(.*)$", absolute, text,
                  flags=re.MULTILINE)
    # The run's own output settings (a scene may set an entry once).
    text = re.sub(r"^\s*set\s+(Write files|Folder|Pictures)\s*=.*$", "",
                  text, flags=re.MULTILINE)
    if refinement:
        # The scene's own checks assume its own sequence of meshes.
        text = re.sub(r"^subsection Verification\n.*?^end\n", "", text,
                      flags=re.MULTILINE | re.DOTALL)
        text = re.sub(r"^\s*set\s+(%s)\s*=.*$" % "|".join(refinement), "",
                      text, flags=re.MULTILINE)
        text += "\nsubsection Refinement\n%send\n" % "".join(
            "  set %s = %s\n" % item for item in refinement.items())
    out = os.path.join(folder, name or os.path.basename(scene)[:-4])
    text += ("\nsubsection Output\n  set Folder = %s\n  set Pictures = false\n"
             "  set Write files = true\n"
             "end\n" % out)
    copy = out + ".prm"
    with open(copy, "w") as f:
        f.write(text)
    result = subprocess.run([binary, copy], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        print(result.stdout[-3000:], result.stderr)
        raise SystemExit("%s: exit code %d" % (scene, result.returncode))
    rows = []
    if os.path.exists(os.path.join(out, "study.csv")):
        with open(os.path.join(out, "study.csv")) as f:
            rows = list(csv.DictReader(f))
    with open(os.path.join(out, "summary.json")) as f:
        return rows, json.load(f)


def main():
    binary = os.path.abspath(sys.argv[1])
    scene_dir = sys.argv[2] if len(sys.argv) > 2 else ACCURACY
    triples = []
    failures = 0
    with tempfile.TemporaryDirectory() as folder:
        for name, references in SCENES:
            rows = run(binary, os.path.join(scene_dir, name), folder)[0]
            print("%s: cycle, dofs, quantity, value, true error, bar "
                  "(relative), bar / true error" % name)
            for row in rows:
                cycle = int(row["cycle"])
                for quantity, column, bar_column in (
                        ("peak", "peak_pressure",
                         "estimated_peak_pressure_error"),
                        ("energy", "energy", "estimated_energy_error")):
                    reference, uncertainty = references[quantity]
                    value = float(row[column])
                    true = abs(value - reference) / abs(reference)
                    bar = float(row[bar_column])
                    if cycle >= 1 and not math.isfinite(bar):
                        print("FAIL: %s cycle %d %s: no error bar" %
                              (name, cycle, quantity))
                        failures += 1
                    ratio = bar / true if true > 0 else math.inf
                    print("  %d %7s %-6s %.7e %.2e %.2e %6.2f" %
                          (cycle, row["dofs"], quantity, value, true, bar,
                           ratio))
                    if cycle >= 2:
                        triples.append((name, quantity, cycle, true, bar,
                                        uncertainty))
    ok = failures == 0
    # Target mode: refine until the bar of the quantity is below the target,
    # then the true error must be below it too.
    with tempfile.TemporaryDirectory() as folder:
        for name, strategy, cycles, quantity, target, reference in (
                ("two_rings.prm", "global", 8, "peak pressure", 0.02,
                 SCENES[2][1]["peak"][0]),
                ("two_rings.prm", "global", 8, "energy", 1e-4,
                 SCENES[2][1]["energy"][0]),
                ("knee.prm", "adaptive", 10, "peak pressure", 0.005,
                 SCENES[0][1]["peak"][0]),
                ("knee.prm", "adaptive", 10, "energy", 5e-4,
                 SCENES[0][1]["energy"][0])):
            settings = {"Strategy": strategy, "Number of cycles": cycles,
                        "Target error": target, "Target quantity": quantity}
            if strategy == "adaptive":
                settings["Number of adaptive cycles"] = cycles
            rows, summary = run(binary, os.path.join(scene_dir, name),
                                folder, settings,
                                "target_%s_%s" % (name[:-4], quantity[0]))
            estimate = summary["error_estimates"][quantity]
            value = estimate["value"]
            true = abs(value - reference) / abs(reference)
            reached = estimate["error"] is not None and \
                estimate["error"] <= target * abs(value)
            passed = reached and true <= target
            print("check target %s %g on %s: %d cycles, %d dofs, value "
                  "%.7e +- %.2e (%s), true error %.2e: %s" %
                  (quantity, target, name, len(rows) or 1, summary["n_dofs"],
                   value, estimate["error"] or float("nan"), estimate["basis"],
                   true, "PASS" if passed else "FAIL"))
            ok = ok and passed
    for quantity, asserted in (("energy", True), ("peak", False)):
        mine = [t for t in triples if t[1] == quantity]
        inside = [t for t in mine if t[3] <= t[4]]
        judged = [t for t in mine if t[3] > 3 * t[5]]
        tight = [t for t in judged if t[4] <= 5 * t[3]]
        share_inside = len(inside) / len(mine)
        share_tight = len(tight) / len(judged) if judged else 0
        print("%s, %d (scene, cycle) pairs after the first two cycles: true "
              "error within the bar in %d (%.0f %%), bar <= 5 x true error "
              "in %d of %d judged (%.0f %%)%s" %
              (quantity, len(mine), len(inside), 100 * share_inside,
               len(tight), len(judged), 100 * share_tight,
               "" if asserted else " (reported, not asserted: issue 24)"))
        for t in mine:
            if t not in inside:
                print("  outside: %s %s cycle %d: true %.2e, bar %.2e" %
                      t[:5])
        for t in judged:
            if t not in tight:
                print("  loose: %s %s cycle %d: true %.2e, bar %.2e" % t[:5])
        if asserted:
            passed = share_inside >= 0.9 and share_tight >= 0.9
            print("check %s: true error within the bar in >= 90 %% and bar "
                  "<= 5 x true error in >= 90 %%: %s" %
                  (quantity, "PASS" if passed else "FAIL"))
            ok = ok and passed
    if not ok:
        raise SystemExit(1)


if __name__ == "__main__":
    main()
