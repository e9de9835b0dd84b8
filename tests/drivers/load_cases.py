#!/usr/bin/python3
"""Load cases against independent single solves.

prm/knee_gait.prm (on a coarser mesh, lc = 0.008, lc_contact = 0.002) is run
once with six load cases on one factorisation, each case starting from the
previous case's active set, with either solver (Contact/Solver = condensed
and step-41). Reference: each t solved on its own (Values of t = that t), a
fresh factorisation starting from the touching pairs. Asserted per case:
the same active pairs (contact_*.csv), the same exit code, and energy,
max |u|, reactions, applied load, interface forces, peak pressures and
tau_yy ranges (summary.json, 17 digits) equal to 1e-10 relative to their
scale (energy; max |u|; the largest force; the largest |tau_yy|).
The cases t = 0, 0.15, 0.3, 0.45, 0.6, 0.8 move the contact zone both ways.
Usage: load_cases.py KNEE_CONTACT
"""
import csv
import json
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "..", "prm", "knee_gait.prm")
GEO = os.path.abspath(os.path.join(HERE, "..", "..", "prm", "knee.geo"))
VALUES = [0, 0.15, 0.3, 0.45, 0.6, 0.8]
TOLERANCE = 1e-10


def scene(folder, name, values, solver):
    text = open(SCENE).read()
    text = text.replace("set File                = knee.geo",
                        "set File                = " + GEO)
    text = re.sub(r"set Gmsh arguments *=.*",
                  "set Gmsh arguments = -setnumber lc 0.008 "
                  "-setnumber lc_contact 0.002", text)
    text = re.sub(r"set Values of t = .*", "set Values of t = " +
                  ", ".join(repr(v) for v in values), text)
    assert GEO in text and "lc_contact 0.002" in text
    text += ("subsection Contact\n  set Solver = %s\nend\n"
             "subsection Output\n  set Folder = %s\n  set Pictures = false\n"
             "end\n" % (solver, os.path.join(folder, name)))
    path = os.path.join(folder, name + ".prm")
    with open(path, "w") as f:
        f.write(text)
    return path


def run(binary, path):
    result = subprocess.run([binary, path], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    if result.returncode != 0:
        print(result.stdout[-2000:])
        raise SystemExit("%s exited with %d" % (path, result.returncode))


def figures(folder):
    """(scalars by scale, active pattern) of one result set."""
    with open(os.path.join(folder, "summary.json")) as f:
        s = json.load(f)
    forces = list(s["applied_load"])
    for r in s["reactions"].values():
        forces += r
    for i in s["contact_interfaces"].values():
        forces.append(i["force"])
    pressures = [i["max_pressure"] for i in s["contact_interfaces"].values()]
    stresses = []
    for m in s["stress_yy"].values():
        stresses += [m["min"], m["max"]]
    active = {}
    for name in sorted(os.listdir(folder)):
        if name.startswith("contact_") and name.endswith(".csv"):
            with open(os.path.join(folder, name)) as f:
                active[name] = [r["active"] for r in csv.DictReader(f)]
    return {"energy": [s["energy"]], "max_displacement":
            [s["max_displacement"]], "forces": forces,
            "pressures": pressures, "stress_yy": stresses}, active


def compare(label, got, reference):
    worst = 0
    for key, values in reference[0].items():
        scale = max(abs(v) for v in values) or 1
        error = max(abs(a - b) for a, b in zip(got[0][key], values)) / scale
        worst = max(worst, error)
        if error > TOLERANCE:
            raise SystemExit("%s: %s differ by %.3e relative > %.0e"
                             % (label, key, error, TOLERANCE))
    if got[1] != reference[1]:
        raise SystemExit("%s: the active pairs differ" % label)
    return worst


def main():
    binary = sys.argv[1]
    with tempfile.TemporaryDirectory() as folder:
        references = []
        for k, t in enumerate(VALUES):
            run(binary, scene(folder, "single_%d" % k, [t], "condensed"))
            references.append(figures(os.path.join(folder, "single_%d" % k)))
        for solver in ("condensed", "step-41"):
            name = "cases_" + solver
            run(binary, scene(folder, name, VALUES, solver))
            for k, t in enumerate(VALUES):
                got = figures(os.path.join(folder, name, "case_%03d" % k))
                worst = compare("%s t = %g" % (solver, t), got, references[k])
                print("%s t = %-5g active pairs and figures as the single "
                      "solve: largest relative difference %.1e <= %.0e"
                      % (solver, t, worst, TOLERANCE))
    print("PASS")


if __name__ == "__main__":
    main()
