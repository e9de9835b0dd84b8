#!/usr/bin/python3
"""The error bars against true errors.

Each scene runs its own mesh sequence; per cycle, study.csv gives the peak
contact pressure and the energy a(u,u) with their estimated relative
errors (the error bars the run reports: the peak pressure's goal-oriented
bar on each mesh, with uniform refinement at least the sequence's; the
energy's strain recovery), and the true error is the distance to a
reference computed independently of the estimators (relative
uncertainty in brackets):
  - tests/accuracy/knee.prm (sagittal knee, 5 adaptive cycles): overkill
    453 698 dofs, peak 8.460989 MPa (1.5e-4: a uniform sequence to 795 270
    dofs extrapolates to 8.4611), a(u,u) = 9.469803 J/m (5e-5);
  - tests/accuracy/knee_frontal.prm (5 adaptive cycles): overkill 708 930
    dofs, peak 7.4985 MPa (5e-5: uniform to 1 160 902 dofs, 7.4987),
    a(u,u) = 7.0609 J/m (2e-4);
  - tests/accuracy/two_rings.prm (6 uniform cycles): Lame's solution,
    contact pressure 16 851 364.2545 Pa, a(u,u) = the internal pressure's
    work p_i u_r(a) pi a / 2 (exact);
  - tests/accuracy/hertz_two_materials.prm, 6 adaptive cycles: two uniform
    sequences (from prm/hertz_two_materials.prm's mesh to 1 358 276 dofs
    and from this one to 1 261 444 dofs, order 1.8 to 2) extrapolate to
    p0 = 0.0317416 (3e-5) and a(u,u) = 6.10895e-5 (2e-5); the adaptive
    sequence itself stalls at 3e-4 above (Kelly leaves the error that sets
    p0 unrefined, and the differences between its cycles fall to 1e-5);
held out (not seen while the estimators were chosen):
  - the same Hertz with the cylinder 2 000 times stiffer than the block (E
    1 000 on 0.5), 6 adaptive cycles: uniform sequence from the example
    mesh to 1 358 276 dofs, p0 = 0.0387840 (2e-5), a(u,u) = 4.290277e-5
    (2e-5);
  - prm/knee_gait.prm on tests/accuracy/knee.prm's mesh, 5 adaptive cycles
    at t = 0.25, then t = 0.5 as a further load case on the last mesh (its
    bars from that one mesh): uniform sequence to 795 270 dofs extrapolated
    with order 2 (the knee's observed order), peaks 6.261909 and 6.996865
    MPa (1.6e-4), a(u,u) = 3.8725920 and 5.4143633 J/m (1.5e-5).
Asserted for the peak pressure and the energy, over the (scene, cycle)
pairs after the first two cycles and the further load case, as issue 24
asks:
  (1) the true error lies within the bar (up to the reference's own
      uncertainty) in at least 90 %;
  (2) the bar is at most 5 times the true error in at least 90 % of the
      pairs whose true error is above 3 times the reference's uncertainty
      (below it the true error is not known well enough to judge a bar by);
and every bar is finite. The held-out scenes are reported on their own too.
Target mode (Refinement/Target error): the two rings (global) to 2 % in the
peak pressure and 1e-4 in the energy, the sagittal knee (adaptive, refined
by the peak pressure's own indicator) to 0.5 % and (Kelly) 5e-4: each run
must stop with its bar below the target, and its true error must be below
the target too.
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
PRM = os.path.normpath(os.path.join(HERE, "..", "..", "prm"))

ADAPTIVE = {"Strategy": "adaptive", "Number of cycles": 6,
            "Number of adaptive cycles": 6, "Refine fraction": 0.3}
# Inner ring of two_rings.prm: u_r = A r + B / r, at r = a = 1.
RING_U_A = 0.00012913561528890945 + 0.0009728390382222736
# (label, scene, {quantity: (reference, relative uncertainty)} for the
# cycles, Refinement entries, other entries {subsection: {name: value}},
# held out, references of the further load case or None).
SCENES = [
    ("knee", "knee.prm",
     {"peak": (8.460989e6, 1.5e-4), "energy": (9.469803, 5e-5)},
     None, {}, False, None),
    ("knee frontal", "knee_frontal.prm",
     {"peak": (7.4985e6, 5e-5), "energy": (7.0609, 2e-4)},
     None, {}, False, None),
    ("two rings", "two_rings.prm",
     {"peak": (16851364.254506525, 1e-12),
      "energy": (1e8 * RING_U_A * math.pi / 2, 1e-12)},
     None, {}, False, None),
    ("Hertz, two materials", "hertz_two_materials.prm",
     {"peak": (0.0317416, 3e-5), "energy": (6.10895e-5, 2e-5)},
     ADAPTIVE, {}, False, None),
    ("Hertz, stiff on soft", "hertz_two_materials.prm",
     {"peak": (0.0387840, 2e-5), "energy": (4.290277e-5, 2e-5)},
     {"Strategy": "global", "Number of cycles": 3},
     {"Materials/Material 0": {"Young's modulus": "1000"}}, True, None),
    ("gait", os.path.join(PRM, "knee_gait.prm"),
     {"peak": (6.261909e6, 1.6e-4), "energy": (3.8725920, 1.5e-5)},
     dict(ADAPTIVE, **{"Number of cycles": 5, "Number of adaptive cycles": 5}),
     {"Mesh": {"Gmsh arguments":
               "-setnumber lc 0.008 -setnumber lc_contact 0.002"},
      "Load cases": {"Values of t": "0.25, 0.5"}},
     True, {"peak": (6.996865e6, 1.6e-4), "energy": (5.4143633, 1.5e-5)}),
]


def with_absolute_mesh(scene):
    """The scene's text with its Mesh/File as an absolute path."""
    with open(scene) as f:
        text = f.read()
    base = os.path.dirname(scene)

    def absolute(match):
        value = match.group(2).strip()
        if value and not os.path.isabs(value):
            value = os.path.normpath(os.path.join(base, value))
        return match.group(1) + value

    return re.sub(r"^(\s*set\s+File\s*=\s*)(.*)$", absolute, text,
                  flags=re.MULTILINE)


def run(binary, scene, folder, refinement=None, name=None, entries=None):
    """The scene with an absolute mesh path, its output in folder (as
    name), with the Refinement entries of @p refinement (a dict) and the
    @p entries ({"Subsection/Sub": {name: value}}) in place of its own;
    the rows of its study.csv, the run's summary.json and the rows of its
    load_cases.csv (empty without load cases)."""
    text = with_absolute_mesh(scene)
    # The run's own output settings (a scene may set an entry once).
    text = re.sub(r"^\s*set\s+(Write files|Folder|Pictures|Terminal)\s*=.*$",
                  "", text, flags=re.MULTILINE)
    if refinement:
        # The scene's own checks assume its own sequence of meshes.
        text = re.sub(r"^subsection Verification\n.*?^end\n", "", text,
                      flags=re.MULTILINE | re.DOTALL)
        text = re.sub(r"^\s*set\s+(%s)\s*=.*$" % "|".join(refinement), "",
                      text, flags=re.MULTILINE)
        text += "\nsubsection Refinement\n%send\n" % "".join(
            "  set %s = %s\n" % item for item in refinement.items())
    for path, values in (entries or {}).items():
        # The entry inside its own subsection (a name such as Young's
        # modulus recurs in other subsections); continuation lines too.
        sections = path.split("/")
        pattern = "".join(r"[ \t]*subsection %s[ \t]*\n(?:.*\n)*?" %
                          re.escape(x) for x in sections)
        for key, value in values.items():
            text, n = re.subn(
                r"(%s\s*set\s+%s\s*=)[^\n]*(?:\\\n[^\n]*)*" %
                (pattern, re.escape(key)),
                lambda m: m.group(1) + " " + value, text, count=1)
            assert n == 1, (scene, path, key)
    out = os.path.join(folder, name or os.path.basename(scene)[:-4])
    text += ("\nsubsection Output\n  set Folder = %s\n  set Pictures = false\n"
             "  set Write files = true\n  set Terminal = test\n"
             "end\n" % out)
    copy = out + ".prm"
    with open(copy, "w") as f:
        f.write(text)
    result = subprocess.run([binary, copy], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        print(result.stdout[-3000:], result.stderr)
        raise SystemExit("%s: exit code %d" % (scene, result.returncode))

    def rows_of(name):
        # With load cases the first case's files are in case_000/.
        for where in (out, os.path.join(out, "case_000")):
            if os.path.exists(os.path.join(where, name)):
                with open(os.path.join(where, name)) as f:
                    return list(csv.DictReader(f))
        return []
    summary = os.path.join(out, "summary.json")
    if not os.path.exists(summary):
        summary = os.path.join(out, "case_000", "summary.json")
    with open(summary) as f:
        return rows_of("study.csv"), json.load(f), rows_of("load_cases.csv")


def judge(name, pairs, failures):
    """Shares of pairs (label, quantity, cycle, true, bar, uncertainty)
    inside and tight; prints them and the misses; True if both >= 90 %."""
    inside = [t for t in pairs if t[3] <= t[4] + t[5]]
    judged = [t for t in pairs if t[3] > 3 * t[5]]
    tight = [t for t in judged if t[4] <= 5 * t[3]]
    share_inside = len(inside) / len(pairs) if pairs else 0
    share_tight = len(tight) / len(judged) if judged else 0
    print("%s: %d pairs: true error within the bar in %d (%.0f %%), bar "
          "<= 5 x true error in %d of %d judged (%.0f %%)" %
          (name, len(pairs), len(inside), 100 * share_inside, len(tight),
           len(judged), 100 * share_tight))
    for t in pairs:
        if t not in inside:
            print("  outside: %s %s cycle %s: true %.2e, bar %.2e" % t[:5])
    for t in judged:
        if t not in tight:
            print("  loose: %s %s cycle %s: true %.2e, bar %.2e" % t[:5])
    return share_inside >= 0.9 and share_tight >= 0.9


def main():
    binary = os.path.abspath(sys.argv[1])
    scene_dir = sys.argv[2] if len(sys.argv) > 2 else ACCURACY
    pairs = []
    failures = 0
    with tempfile.TemporaryDirectory() as folder:
        for label, scene, references, refinement, entries, held_out, \
                further in SCENES:
            path = scene if os.path.isabs(scene) else \
                os.path.join(scene_dir, scene)
            rows, _, cases = run(binary, path, folder, refinement,
                                 re.sub(r"\W+", "_", label), entries)
            print("%s: cycle, dofs, quantity, value, true error, bar "
                  "(relative), bar / true error" % label)
            measured = [(row["cycle"], row["dofs"], float(row[column]),
                         float(row[bar_column]), quantity, references)
                        for row in rows
                        for quantity, column, bar_column in (
                            ("peak", "peak_pressure",
                             "estimated_peak_pressure_error"),
                            ("energy", "energy", "estimated_energy_error"))]
            if further:
                # The further load case: its bars from its one mesh.
                case = cases[1]
                peak = max(float(case[k]) for k in case
                           if k.endswith("_peak_pressure"))
                measured += [
                    ("t=" + case["t"], "", peak,
                     float(case["peak_pressure_error"]) / peak, "peak",
                     further),
                    ("t=" + case["t"], "", float(case["energy"]),
                     float(case["energy_error"]) / float(case["energy"]),
                     "energy", further)]
            for cycle, dofs, value, bar, quantity, refs in measured:
                reference, uncertainty = refs[quantity]
                true = abs(value - reference) / abs(reference)
                if not math.isfinite(bar):
                    print("FAIL: %s cycle %s %s: no error bar" %
                          (label, cycle, quantity))
                    failures += 1
                print("  %4s %7s %-6s %.7e %.2e %.2e %6.2f" %
                      (cycle, dofs, quantity, value, true, bar,
                       bar / true if true > 0 else math.inf))
                if not cycle.isdigit() or int(cycle) >= 2:
                    pairs.append((label, quantity, cycle, true, bar,
                                  uncertainty, held_out))
    ok = failures == 0
    # Target mode: refine until the bar of the quantity is below the target,
    # then the true error must be below it too.
    with tempfile.TemporaryDirectory() as folder:
        for name, strategy, cycles, quantity, target, reference in (
                ("two_rings.prm", "global", 8, "peak pressure", 0.02,
                 SCENES[2][2]["peak"][0]),
                ("two_rings.prm", "global", 8, "energy", 1e-4,
                 SCENES[2][2]["energy"][0]),
                ("knee.prm", "adaptive", 10, "peak pressure", 0.005,
                 SCENES[0][2]["peak"][0]),
                ("knee.prm", "adaptive", 10, "energy", 5e-4,
                 SCENES[0][2]["energy"][0])):
            settings = {"Strategy": strategy, "Number of cycles": cycles,
                        "Target error": target, "Target quantity": quantity}
            if strategy == "adaptive":
                settings["Number of adaptive cycles"] = cycles
            rows, summary, _ = run(binary, os.path.join(scene_dir, name),
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
    for quantity in ("peak", "energy"):
        mine = [t[:6] for t in pairs if t[1] == quantity]
        held = [t[:6] for t in pairs if t[1] == quantity and t[6]]
        judge("%s, held-out scenes (reported)" % quantity, held, failures)
        passed = judge("%s, all scenes" % quantity, mine, failures)
        print("check %s: true error within the bar in >= 90 %% and bar "
              "<= 5 x true error in >= 90 %%: %s" %
              (quantity, "PASS" if passed else "FAIL"))
        ok = ok and passed
    if not ok:
        raise SystemExit(1)


if __name__ == "__main__":
    main()
