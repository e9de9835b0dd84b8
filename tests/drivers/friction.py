#!/usr/bin/python3
"""Friction (Coulomb) against independent references, loaded in one step.

1. mu = 0 reproduces the frictionless results: each contact scene
   (contact patch on matching and non-matching meshes, the mixed mesh, the
   two-material Hertz, the sagittal knee) is run as it is and with
   Friction = coulomb, Friction coefficient = 0 on every interface (both
   on the sparse solver path); every number of summary.json (energy,
   reactions, forces, pressures, stresses, ...) must agree to 1e-12
   relative to the largest of its kind (the knee: 1e-10, see FRICTIONLESS).
2. A very large mu reproduces the bonded solution on matching meshes: a
   block (0.5 x 0.25, 4 x 2 cells) on a base (1 x 0.5, 8 x 4) with the
   base's bottom held and the block's top loaded by (2e5, -1e6) Pa, with
   mu = 1e3 (every pair sticks) against the same rectangles sharing their
   vertices (bonded, no interface): energy, max |u| and reactions to 1e-10.
3. Statics of the block, held by friction only (its sides free), load
   ratio r = 0.2 tangential/normal: with mu = 0.5 > r it sticks and the
   interface force (normal plus tangential on the slave) balances the
   load to 1e-8 relative (node-to-node, node-to-segment and mortar); with
   mu = 0.1 < r the run is refused in one line naming the ratio 0.2.
4. The NAFEMS CGS-4 threshold on an inclined interface: the block on a
   base both tilted by a = 20 degrees (non-matching meshes), mu = 0.3,
   pushed by a horizontal force F and a vertical G (a traction on its top
   side): it stays iff F/G <= (tan a + mu) / (1 - mu tan a) = 0.7454. At
   0.97 times the threshold the interface force balances the load to 1e-8
   (node-to-segment and mortar); at 1.03 times the run is refused in one
   line naming the ratio the block needs along the tilted interface,
   (F cos a - G sin a) / (F sin a + G cos a) = 0.316, to 3 digits.
5. Tresca on a strip: an elastic strip (1 x 0.01, 100 x 2 cells, E = 1e9,
   nu = 0, plane stress) pressed (1e6 Pa) onto a base 1e4 times stiffer
   and pulled at its right end by F = 4e4 N/m, slip bound g = 1e5 Pa. Bar
   theory: the strip slips over the length l = F/g = 0.4 from the pulled
   end and sticks beyond; the end moves by g l^2 / (2 E h) = 8e-4 m.
   Asserted: the stick/slip boundary (midway between the last sticking and
   the first slipping vertex) to the strip's height h (measured 0.5 h; the
   2D strip's shear lag, 0.75 h at h = 0.02, 0.5 h at h = 0.005) and the
   end's displacement to 1 % (measured 0.1 %; 0.5 % at h = 0.02, 0.03 %
   at h = 0.005).
Usage: friction.py KNEE_CONTACT
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
SCENES = os.path.join(HERE, "..", "scenes")
# Scene and tolerance. The rows of friction enter the sparsity pattern, so
# the factorisation's ordering differs and the results differ by round-off:
# 1e-14 on the patch tests, 8e-14 on Hertz; the knee's moduli span 1.1e9 to
# 2e11, which amplifies it to 1.5e-11 (measured): 1e-10 there.
FRICTIONLESS = [("contact_patch_matching.prm", 1e-12),
                ("contact_patch_nonmatching.prm", 1e-12),
                ("contact_patch_mixed.prm", 1e-12), ("hertz_small.prm", 1e-12),
                ("knee_small.prm", 1e-10)]

MATERIALS = """subsection Materials
  set Number of materials = 2
  subsection Material 0
    set Material id     = 1
    set Name            = base
    set Young's modulus = 1e9
    set Poisson's ratio = 0.3
  end
  subsection Material 1
    set Material id     = 2
    set Name            = block
    set Young's modulus = 3e9
    set Poisson's ratio = 0.2
  end
end
"""

BLOCK = """
subsection Mesh
  set Source     = rectangles
  set Rectangles = 0, 0, 1, 0.5, 8, 4, 1, 0, 1, 1, 2, 3; \\
                   0.25, 0.5, 0.75, 0.75, 4, 2, 2, {group}, 4, 4, 5, 6
end
{materials}subsection Boundary conditions
  set Number of conditions = 2
  subsection Condition 0
    set Boundary ids = 2
    set Type         = displacement
  end
  subsection Condition 1
    set Boundary ids = 6
    set Type         = traction
    set Value        = 2e5; -1e6
  end
end
subsection Contact
  set Number of interfaces = {n_interfaces}
{interface}
end
subsection Output
  set Folder   = {folder}
  set Pictures = false
end
"""

INTERFACE = """  subsection Interface 0
    set Name                 = block
    set Slave boundary id    = 5
    set Master boundary id   = 3
    set Pairing              = {pairing}
    set Friction             = coulomb
    set Friction coefficient = {mu}
  end"""


# A block (1 x 0.25, 8 x 2 cells) on a base (3 x 1, 13 x 4), both turned
# by {angle} degrees about the origin; curves: 1 base bottom, 3 base top,
# 5 block bottom, 6 block top.
INCLINED_GEO = """
Geometry.AutoCoherence = 0;
Point(1) = {{-1.5, -1, 0}}; Point(2) = {{1.5, -1, 0}};
Point(3) = {{1.5, 0, 0}}; Point(4) = {{-1.5, 0, 0}};
Point(5) = {{-0.5, 0, 0}}; Point(6) = {{0.5, 0, 0}};
Point(7) = {{0.5, 0.25, 0}}; Point(8) = {{-0.5, 0.25, 0}};
Line(1) = {{1, 2}}; Line(2) = {{2, 3}}; Line(3) = {{3, 4}}; Line(4) = {{4, 1}};
Line(5) = {{5, 6}}; Line(6) = {{6, 7}}; Line(7) = {{7, 8}}; Line(8) = {{8, 5}};
Curve Loop(1) = {{1, 2, 3, 4}}; Plane Surface(1) = {{1}};
Curve Loop(2) = {{5, 6, 7, 8}}; Plane Surface(2) = {{2}};
Transfinite Curve{{1, 3}} = 14; Transfinite Curve{{2, 4}} = 5;
Transfinite Curve{{5, 7}} = 9; Transfinite Curve{{6, 8}} = 3;
Transfinite Surface{{1, 2}}; Recombine Surface{{1, 2}};
Rotate {{{{0, 0, 1}}, {{0, 0, 0}}, {angle} * Pi / 180}} {{ Surface{{1, 2}}; }}
Physical Surface(1) = {{1}}; Physical Surface(2) = {{2}};
Physical Curve(1) = {{1}}; Physical Curve(3) = {{3}};
Physical Curve(5) = {{5}}; Physical Curve(6) = {{7}};
"""

INCLINED = """
subsection Mesh
  set Source = file
  set File   = {geo}
end
{materials}subsection Boundary conditions
  set Number of conditions = 2
  subsection Condition 0
    set Boundary ids = 1
    set Type         = displacement
  end
  subsection Condition 1
    set Boundary ids = 6
    set Type         = traction
    set Value        = {fx}; {fy}
  end
end
subsection Contact
  set Number of interfaces = 1
{interface}
end
subsection Output
  set Folder   = {folder}
  set Pictures = false
end
"""


STRIP = """
subsection Mesh
  set Source     = rectangles
  set Rectangles = 0, -0.1, 1.2, 0, 60, 5, 1, 0, 7, 8, 1, 2; \\
                   0, 0, 1, 0.01, 100, 2, 2, 1, 5, 9, 4, 6
end
subsection Materials
  set Number of materials = 2
  set Plane               = stress
  subsection Material 0
    set Material id     = 1
    set Name            = base
    set Young's modulus = 1e13
    set Poisson's ratio = 0
  end
  subsection Material 1
    set Material id     = 2
    set Name            = strip
    set Young's modulus = 1e9
    set Poisson's ratio = 0
  end
end
subsection Boundary conditions
  set Number of conditions = 3
  subsection Condition 0
    set Boundary ids = 1
    set Type         = displacement
  end
  subsection Condition 1
    set Boundary ids = 6
    set Type         = pressure
    set Value        = 1e6
  end
  subsection Condition 2
    set Boundary ids = 9
    set Type         = traction
    set Value        = 4e6; 0
  end
end
subsection Contact
  set Number of interfaces = 1
  subsection Interface 0
    set Name               = strip
    set Slave boundary id  = 4
    set Master boundary id = 2
    set Pairing            = node-to-segment
    set Friction           = tresca
    set Tresca bound       = 1e5
  end
end
subsection Output
  set Folder   = {folder}
  set Pictures = false
end
"""


def run_scene(binary, text, folder, name, expect_success=True):
    """Write the scene as folder/name.prm and run it; unless told it may
    fail, a non-zero exit ends the test with the run's output."""
    scene = os.path.join(folder, name + ".prm")
    with open(scene, "w") as f:
        f.write(text)
    result = subprocess.run([binary, scene], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    if expect_success and result.returncode != 0:
        print(result.stdout[-2000:], result.stderr)
        raise SystemExit("%s: exit code %d" % (name, result.returncode))
    return result


def run(binary, text, folder, name, expect_success=True):
    """run_scene(); its summary.json if it must succeed, else the run."""
    result = run_scene(binary, text, folder, name, expect_success)
    if not expect_success:
        return result
    with open(os.path.join(folder, name, "summary.json")) as f:
        return json.load(f)


# What numbers() leaves out by default (see there).
NOT_COMPARED = ("wall_time", "solver", "tangential_force_on_slave",
                "n_stick", "n_slip", "max_slip", "stick_length",
                "slip_length", "stick_area", "slip_area",
                "max_accumulated_slip",
                "active_set_iterations", "error_estimates",
                "max_pressure_error", "energy_error", "force_error",
                "min_error", "max_error", "peak_location")


def numbers(value, path="", skipped=NOT_COMPARED):
    """(path, number) of summary.json but the entries named in @p skipped:
    by default timings, solver figures, the
    friction entries (which the frictionless run has not), the error
    bars made from the contact solution (a frictionless run has the
    goal-oriented bars of each peak pressure and force and imposes the
    contact tractions in the strain recovery of the energy's and the
    stress extremes' bars, a frictional one not: their methods differ) and
    the peak pressure's location (under a uniform pressure every pair ties
    up to round-off, and either run may name another)."""
    if isinstance(value, dict):
        for k, v in value.items():
            if k not in skipped:
                yield from numbers(v, path + "/" + k, skipped)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from numbers(v, path + "[%d]" % i, skipped)
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        yield path, float(value)


def kind_of(key):
    """The kind of a summary.json number, the scale of its differences:
    its top-level entry, every stress one kind (a patch test's zero
    components are round-off beside the others)."""
    top = key.split("/")[1]
    return "stress" if "stress" in top or "mises" in top else top


def compare(name, reference, other, tolerance, kind=lambda key:
            key.split("/")[1]):
    """Every number of two summaries, relative to the largest of its
    @p kind in the reference."""
    a, b = dict(numbers(reference)), dict(numbers(other))
    assert a.keys() == b.keys(), (name, a.keys() ^ b.keys())
    worst, failures = 0.0, 0
    for key in a:
        if kind(key) in ("equilibrium_residual", "relative_max_penetration",
                         "complementarity_residual", "max_penetration"):
            continue  # round-off measures
        scale = max(abs(v) for k, v in a.items()
                    if kind(k) == kind(key)) or 1.0
        error = abs(a[key] - b[key]) / scale
        worst = max(worst, error)
        if error > tolerance:
            print("FAIL %s: %s = %r, reference %r" % (name, key, b[key],
                                                     a[key]))
            failures += 1
    print("%s: %d numbers, largest relative difference %.1e (tolerance "
          "%.0e)" % (name, len(a), worst, tolerance))
    return failures


def with_output(text, folder):
    """The scene with its files written into folder."""
    text = re.sub(r"\n\s*set Terminal\s*=.*", "", text)
    text = re.sub(r"\n\s*set Write files\s*=.*", "", text)
    text = re.sub(r"\n\s*set Folder\s*=.*", "", text)
    return text.replace("subsection Output",
                        "subsection Output\n  set Folder = %s\n"
                        "  set Pictures = false" % folder, 1)


def mu_zero_runs(binary, folder, scenes, run_one):
    """For each (scene, tolerance) of tests/scenes: the scene and its copy
    with Friction = coulomb, Friction coefficient = 0 on every interface,
    both run by @p run_one on the sparse path (the automatic choice weighs
    the number of rows, which friction doubles; paths differ by round-off):
    yields (name, tolerance, frictionless result, frictional result)."""
    for scene, tolerance in scenes:
        text = open(os.path.join(SCENES, scene)).read()
        # Relative paths of the scene (meshes) from the scenes folder.
        text = re.sub(r"(set File\s*=\s*)(\S+)",
                      lambda m: m.group(1) + os.path.normpath(
                          os.path.join(SCENES, m.group(2))), text)
        name = scene[:-4]
        text = re.sub(r"\n\s*set Solver\s*=.*", "", text)
        text = text.replace("subsection Contact",
                            "subsection Contact\n  set Solver = sparse", 1)
        plain = run_one(binary,
                        with_output(text, os.path.join(folder, name)),
                        folder, name)
        frictional = re.sub(
            r"(\n(\s*)subsection Interface \d+)",
            lambda m: m.group(1) + "\n" + m.group(2) +
            "  set Friction = coulomb\n" + m.group(2) +
            "  set Friction coefficient = 0", text)
        assert frictional != text
        other = run_one(binary,
                        with_output(frictional,
                                    os.path.join(folder, name + "_mu0")),
                        folder, name + "_mu0")
        yield name, tolerance, plain, other


def main():
    binary = os.path.abspath(sys.argv[1])
    failures = 0
    with tempfile.TemporaryDirectory() as folder:
        # 1. mu = 0.
        for name, tolerance, plain, other in mu_zero_runs(
                binary, folder, FRICTIONLESS, run):
            failures += compare(name + ", mu = 0", plain, other, tolerance)

        # 2. Very large mu against bonded rectangles.
        bonded = run(binary, BLOCK.format(
            materials=MATERIALS, group=0, n_interfaces=0, interface="",
            folder=os.path.join(folder, "bonded")), folder, "bonded")
        sticking = run(binary, BLOCK.format(
            materials=MATERIALS, group=1, n_interfaces=1,
            interface=INTERFACE.format(pairing="node-to-node", mu=1e3),
            folder=os.path.join(folder, "sticking")), folder, "sticking")
        assert sticking["contact_interfaces"]["block"]["n_slip"] == 0
        for key in ("energy", "max_displacement"):
            error = abs(sticking[key] - bonded[key]) / abs(bonded[key])
            print("mu = 1e3 against bonded: %s %.1e (tolerance 1e-10)"
                  % (key, error))
            failures += error > 1e-10
        for k, v in bonded["reactions"].items():
            w = sticking["reactions"][k]
            reaction = w if isinstance(w, list) else w["force"]
            reference = v if isinstance(v, list) else v["force"]
            error = max(abs(x - y) for x, y in zip(reaction, reference)) / \
                max(abs(x) for x in reference)
            print("mu = 1e3 against bonded: reaction %s %.1e (tolerance "
                  "1e-10)" % (k, error))
            failures += error > 1e-10

        # 3. Statics of the block held by friction.
        load = (2e5 * 0.5, -1e6 * 0.5)
        for pairing in ("node-to-node", "node-to-segment", "mortar"):
            name = "statics_" + pairing
            summary = run(binary, BLOCK.format(
                materials=MATERIALS, group=1, n_interfaces=1,
                interface=INTERFACE.format(pairing=pairing, mu=0.5),
                folder=os.path.join(folder, name)), folder, name)
            interface = summary["contact_interfaces"]["block"]
            total = [interface["force_on_slave"][d] +
                     interface["tangential_force_on_slave"][d] + load[d]
                     for d in range(2)]
            error = max(abs(x) for x in total) / abs(load[1])
            print("%s, mu = 0.5 > 0.2: interface force + load = %s, "
                  "relative %.1e (tolerance 1e-8); %d sticking"
                  % (pairing, total, error, interface["n_stick"]))
            failures += error > 1e-8
            refused = run(binary, BLOCK.format(
                materials=MATERIALS, group=1, n_interfaces=1,
                interface=INTERFACE.format(pairing=pairing, mu=0.1),
                folder=os.path.join(folder, name + "_slides")), folder,
                name + "_slides", expect_success=False)
            lines = refused.stderr.strip().splitlines()
            ok = (refused.returncode == 1 and len(lines) == 1 and
                  "friction cannot hold it" in lines[0] and
                  "tangential/normal force 0.2)" in lines[0])
            print("%s, mu = 0.1 < 0.2: exit %d, %s" %
                  (pairing, refused.returncode, lines[-1] if lines else ""))
            failures += not ok

        # 4. NAFEMS CGS-4: the threshold on an inclined interface.
        angle, mu, G = 20.0, 0.3, 1e6
        a = math.radians(angle)
        threshold = (math.tan(a) + mu) / (1 - mu * math.tan(a))
        geo = os.path.join(folder, "inclined.geo")
        with open(geo, "w") as f:
            f.write(INCLINED_GEO.format(angle=angle))
        for pairing in ("node-to-segment", "mortar"):
            for factor in (0.97, 1.03):
                F = factor * threshold * G
                name = "inclined_%s_%g" % (pairing, factor)
                # The traction on the top side (length 1): force (F, -G).
                text = INCLINED.format(
                    geo=geo, fx=F, fy=-G, materials=MATERIALS,
                    interface=INTERFACE.format(pairing=pairing, mu=mu),
                    folder=os.path.join(folder, name))
                if factor < 1:
                    # On every solver path: step-41's takes the Coulomb
                    # bound mu lambda_n of the last solve (a fixed point),
                    # the others the Newton step, each in its own algebra
                    # (the condensed path's dense multiplier system, GMRES
                    # on the sparse factor and on AMG): they must agree,
                    # and the Newton step must not take more iterations.
                    found = {}
                    for solver in ("step-41", "condensed", "sparse",
                                   "iterative"):
                        text = INCLINED.format(
                            geo=geo, fx=F, fy=-G, materials=MATERIALS,
                            interface=INTERFACE.format(pairing=pairing,
                                                       mu=mu),
                            folder=os.path.join(folder, name + solver))
                        summary = run(binary, text.replace(
                            "subsection Contact\n",
                            "subsection Contact\n  set Solver = %s\n"
                            % solver, 1), folder, name + solver)
                        found[solver] = summary
                        interface = summary["contact_interfaces"]["block"]
                        total = [interface["force_on_slave"][d] +
                                 interface["tangential_force_on_slave"][d] +
                                 (F, -G)[d] for d in range(2)]
                        error = max(abs(x) for x in total) / G
                        print("CGS-4 %s, F/G = %.4f (threshold %.4f), %s: "
                              "interface force + load relative %.1e "
                              "(tolerance 1e-8); %d sticking, %d slipping, "
                              "%d iterations" %
                              (pairing, F / G, threshold, solver, error,
                               interface["n_stick"], interface["n_slip"],
                               summary["active_set_iterations"]))
                        failures += error > 1e-8
                    for solver in ("condensed", "sparse", "iterative"):
                        difference = max(
                            abs(found[solver][key] - found["step-41"][key]) /
                            abs(found["step-41"][key])
                            for key in ("energy", "max_displacement"))
                        coupled = found[solver]["solver"]["coupled_solves"]
                        print("  %s against step-41: energy and max |u| "
                              "%.1e (tolerance 1e-8), %d iterations against "
                              "%d, %g coupled solves (must be > 0)"
                              % (solver, difference,
                                 found[solver]["active_set_iterations"],
                                 found["step-41"]["active_set_iterations"],
                                 coupled))
                        failures += difference > 1e-8 or coupled == 0 or \
                            found[solver]["active_set_iterations"] > \
                            found["step-41"]["active_set_iterations"]
                else:
                    ratio = (F * math.cos(a) - G * math.sin(a)) / (
                        F * math.sin(a) + G * math.cos(a))
                    refused = run(binary, text, folder, name,
                                  expect_success=False)
                    lines = refused.stderr.strip().splitlines()
                    ok = (refused.returncode == 1 and len(lines) == 1 and
                          "friction cannot hold it" in lines[0] and
                          "tangential/normal force %.3g)" % ratio in lines[0])
                    print("CGS-4 %s, F/G = %.4f > %.4f: exit %d, needs %.3g: "
                          "%s" % (pairing, F / G, threshold,
                                  refused.returncode, ratio,
                                  lines[-1] if lines else ""))
                    failures += not ok

        # 5. Tresca: the slip zone of a strip pulled at one end.
        strip = os.path.join(folder, "strip")
        summary = run(binary, STRIP.format(folder=strip), folder, "strip")
        with open(os.path.join(strip, "contact_strip.csv")) as f:
            rows = list(csv.DictReader(f))
        stick = [float(r["x"]) for r in rows if r["status"] == "stick"]
        slip = [float(r["x"]) for r in rows if r["status"] == "slip"]
        h, g, F, E = 0.01, 1e5, 4e4, 1e9
        boundary = (max(stick) + min(slip)) / 2
        error = abs(boundary - (1 - F / g)) / h
        print("Tresca strip: stick/slip boundary at x = %.4f, analytic %.4f: "
              "%.2f strip heights (tolerance 1)" % (boundary, 1 - F / g,
                                                    error))
        failures += error > 1 or min(slip) < max(stick)
        end = g * (F / g) ** 2 / (2 * E * h)
        error = abs(summary["max_displacement"] - end) / end
        print("Tresca strip: end displacement %.5e, bar theory %.5e: "
              "relative %.1e (tolerance 1e-2)" %
              (summary["max_displacement"], end, error))
        failures += error > 1e-2
    if failures:
        raise SystemExit("%d failures" % failures)


if __name__ == "__main__":
    main()
