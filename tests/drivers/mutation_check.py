#!/usr/bin/env python3
"""Mutation check: proves that each physics test can fail.

For every scene given, each physical input is perturbed by 1 %, one at a
time, in a copy of the scene:
  E        every material's Young's modulus        x 1.01
  nu       every material's Poisson's ratio        x 1.01
  mu       every interface's Friction coefficient and Tresca bound x 1.01
  load     every non-zero condition value and body force x 1.01
  geometry every coordinate x 1.01 (Rectangles; a .geo gets
           Mesh.ScalingFactor = 1.01; circle centres scaled too)
and the program is run on the copy as ctest runs the test, without numdiff.
Each mutant must make the test's own verification checks fail (exit code 2).
A mutant that passes (exit 0) means the test cannot see a 1 % error of that
input: the check fails and names it. Exit 1 or 3 of a mutant is an error of
this script or of the scene.

Exempt mutations are listed in EXEMPT below, each with the reason; nothing
else is skipped.

Usage: mutation_check.py PROGRAM SCENE...
"""

import concurrent.futures
import os
import re
import shutil
import subprocess
import sys
import tempfile

FACTOR = 1.01

# (scene file name, regular expression matched against the mutation's
# kind and description "kind: description"): reason.
EXEMPT = [
    ("zero_load.prm", r".",
     "no load: the exact solution is u = 0 for any E, nu and geometry"),
    ("contact_separation.prm", r"^(E|nu):",
     "stress-free rigid lift: u does not depend on E or nu"),
    ("large_gap.prm", r"^(E|nu|geometry):",
     "the gap stays open and the lifted body moves rigidly: u does not "
     "depend on E, nu or the size of the blocks"),
    ("friction_sliding_block.prm", r"^(E|nu):|Condition 2: displacement",
     "the whole interface slips: statics fix the normal force G L and the "
     "friction force mu G L for any E and nu and any push that makes every "
     "pair slip"),
    ("friction_sliding_block_3d.prm",
     r"^(E|nu):|Condition 2: displacement",
     "as friction_sliding_block.prm, in 3D"),
    ("uniaxial_block.prm", r"^geometry:",
     "homogeneous strain under a traction: u = eps x holds on a block of "
     "any size, so scaling the block cannot change the answer"),
    ("uniaxial_block_msh22.prm", r"^geometry:", "as uniaxial_block.prm"),
    ("uniaxial_block_msh41.prm", r"^geometry:", "as uniaxial_block.prm"),
    ("uniaxial_block_p1.prm", r"^geometry:", "as uniaxial_block.prm"),
    ("uniaxial_block_3d.prm", r"^geometry:", "as uniaxial_block.prm"),
    ("uniaxial_block_3d_tet.prm", r"^geometry:", "as uniaxial_block.prm"),
    ("uniaxial_block_3d_tet_sliding.prm", r"^geometry:",
     "as uniaxial_block.prm"),
    ("uniaxial_block_3d_tet_adaptive.prm", r"^geometry:",
     "as uniaxial_block.prm"),
    ("manufactured_convergence_3d_tet.prm", r"^(nu|load):",
     "the tetrahedral meshes of the rate test stay coarse (finest relative "
     "L2 error 1.75e-2): a 1 % error of nu or of the body force adds less "
     "than that and the rates stay; the hexahedral twin "
     "manufactured_convergence_3d.prm, same assembly, kills both"),
    ("hertz_sphere_3d_small.prm", r"^nu:",
     "Hertz: nu enters through 1 - nu^2 (0.91 -> 0.908 for nu x 1.01), which "
     "moves E* by 0.2 % and p0, the area and the energy by 0.1-0.15 %, "
     "below this coarse mesh's own error against its references (p0 4.8 %, "
     "energy 0.25 %); nu's 3D contact code is the same as E's, and the 3D "
     "patch tests and the two Lame shells kill nu"),
    ("hertz_sphere_3d_adaptive.prm", r"^nu:",
     "as hertz_sphere_3d_small.prm: nu x 1.01 moves E* by 0.2 %, p0 and the "
     "energy by about 0.1-0.15 %, less than the room left by the finite "
     "model's own error against Hertz (1.5 %) and against its limit "
     "(0.4 %); both E are killed"),
    ("lame_two_shells_contact.prm", r"^nu: Materials/Material 0:",
     "Lame: nu1 x 1.01 moves the exact field by 0.11 % (relative L2, from "
     "the five equations of the two shells), half of the finest mesh's own "
     "error 0.23 %; nu2 (0.12 %) is killed, E1 (0.56 %) too"),
    ("lame_sphere_octant.prm", r"^nu:",
     "analytic: u_r(a) is proportional to (1 - 2 nu) + 4 (1 + nu), so nu "
     "x 1.01 moves it by 0.1 %, below the finest mesh's L2 error (7.4e-3)"),
    ("lame_sphere_octant_sliding.prm", r"^(nu|load):",
     "as lame_sphere_octant.prm: nu x 1.01 moves B by 0.06 % (analytic); "
     "1 % more pressure offsets P1's stiffness (L2 error 5.8e-3, measured, "
     "below the 6.5e-3 of the exact pressure); E x 1.01 is killed"),
    ("lame_sphere_octant.prm", r"^load:",
     "P1 on these meshes is too stiff by about 0.7 % (measured): 1 % more "
     "pressure cancels that and the L2 error falls to 3.4e-3 (measured); "
     "E x 1.01, the same factor the other way, is killed"),
    ("contrast_1e6.prm", r"^E: Materials/Material 1:",
     "the stiff body's E x 1.01 moves u by 1.2e-8 of max |u|, at the "
     "test's 1e-8 tolerance: the solve's round-off at this contrast "
     "(3.9e-10 to 2.3e-9 with the dofs' order) decides whether it is "
     "caught (measured 9.7e-9 in reverse Cuthill-McKee order); the soft "
     "E, both nu, the load and the geometry are killed"),
    ("sliding_rotated_square.prm", r"^geometry:",
     "homogeneous strain: u = eps x on a square of any size"),
    # Measured sensitivities (tests/scenes/knee_small.prm, knee_frontal_small.prm:
    # relative change of a(u,u) / of the peak pressures under x 1.01):
    # bone nu 1.9e-4 / 2.8e-4; Ti6Al4V E 8.1e-5 / 7.0e-5, nu 1.9e-5 /
    # 2.2e-5; ZrO2 E 4.0e-5 / 2.9e-5, nu 5.7e-6 / 3.6e-6; peak pressures
    # below 4e-5 for all of them. The overkill references are known to
    # 5e-5 / 2e-4 and the test meshes are 4.9e-4 / 1.3e-3 from them.
    ("knee.prm", r"^nu: Materials/Material 0:|Material [13]:",
     "bone's nu and the stiff components' (Ti6Al4V, ZrO2) E and nu move "
     "the energy by less than 3e-4 and the peak pressure by less than "
     "4e-5: below the test mesh's error against the overkill"),
    ("knee_frontal.prm", r"^nu: Materials/Material 0:|Material [13]:",
     "as tests/accuracy/knee.prm"),
    ("hertz_two_materials.prm", r"^nu: Materials/Material 0:",
     "1 % of the cylinder's nu = 0.25 changes its 1 - nu^2 by 0.13 % and "
     "E* by 0.05 %, the energy by about 5e-4: at the test mesh's own error "
     "against the overkill (5.4e-4)"),
    ("knee_small.prm", r".",
     "coarse-mesh regression scene (statics asserted); "
     "tests/accuracy/knee.prm verifies the model against its overkill"),
    ("knee_frontal_small.prm", r".",
     "coarse-mesh regression scene (statics asserted); "
     "tests/accuracy/knee_frontal.prm verifies the model"),
]

def logical_lines(text):
    """(first line index, last line index, joined text) of each logical
    line (backslash continuations joined)."""
    lines = text.split("\n")
    result = []
    i = 0
    while i < len(lines):
        start = i
        joined = lines[i]
        while joined.rstrip().endswith("\\") and i + 1 < len(lines):
            joined = joined.rstrip()[:-1] + " " + lines[i + 1].strip()
            i += 1
        result.append((start, i, joined))
        i += 1
    return lines, result


SET = re.compile(r"^(\s*set\s+)([^=]+?)(\s*=\s*)(.*)$")


def entries(text):
    """Yield (path, name, value, start, end) of every `set`."""
    lines, logical = logical_lines(text)
    stack = []
    for start, end, line in logical:
        stripped = line.split("#", 1)[0].strip()
        if stripped.startswith("subsection "):
            stack.append(stripped[len("subsection "):].strip())
        elif stripped == "end":
            stack.pop()
        else:
            m = SET.match(line.split("#", 1)[0])
            if m:
                yield ("/".join(stack), m.group(2).strip(),
                       m.group(4).strip(), start, end)


def replace_entry(text, start, end, name, value):
    lines = text.split("\n")
    indent = re.match(r"^\s*", lines[start]).group(0)
    lines[start:end + 1] = [f"{indent}set {name} = {value}"]
    return "\n".join(lines)


def is_zero(value):
    return all(re.fullmatch(r"\s*[-+]?0*\.?0*(e[-+]?\d+)?\s*", c or "0")
               for c in value.split(";"))


def scaled_expression(value):
    return "; ".join(f"({c.strip()})*{FACTOR}" if c.strip() else c
                     for c in value.split(";"))


def scale_number(text):
    return repr(float(text) * FACTOR)


def mutants(scene_path):
    """Yield (kind, description, scene text, extra files by name)."""
    text = open(scene_path).read()
    found = list(entries(text))
    types = {}
    for path, name, value, start, end in found:
        if name == "Type":
            types[path] = value
    for path, name, value, start, end in found:
        if name == "Young's modulus":
            yield ("E", f"{path}: E x {FACTOR}",
                   replace_entry(text, start, end, name, scale_number(value)),
                   {})
        elif name == "Poisson's ratio":
            # Near 0.5 the 1 % goes down, so that nu stays admissible.
            factor = FACTOR if float(value) * FACTOR < 0.5 else 2 - FACTOR
            yield ("nu", f"{path}: nu x {factor}",
                   replace_entry(text, start, end, name,
                                 repr(float(value) * factor)), {})
        elif name in ("Friction coefficient", "Tresca bound") and \
                not is_zero(value):
            yield ("mu", f"{path}: {name} x {FACTOR}",
                   replace_entry(text, start, end, name, scale_number(value)),
                   {})
        elif name == "Body force" and not is_zero(value):
            yield ("load", f"{path}: body force x {FACTOR}",
                   replace_entry(text, start, end, name,
                                 scaled_expression(value)), {})
        elif (name == "Value" and types.get(path, "displacement")
              in ("displacement", "traction", "pressure")
              and not is_zero(value)):
            yield ("load", f"{path}: {types.get(path, 'displacement')} "
                   f"x {FACTOR}",
                   replace_entry(text, start, end, name,
                                 scaled_expression(value)), {})
    # Geometry: every coordinate x FACTOR.
    geometry = text
    geometry_files = {}
    changed = False
    for path, name, value, start, end in reversed(found):
        if path == "Mesh" and name == "Rectangles":
            rectangles = []
            for r in value.split(";"):
                fields = [f.strip() for f in r.split(",")]
                fields[:4] = [scale_number(f) for f in fields[:4]]
                rectangles.append(", ".join(fields))
            geometry = replace_entry(geometry, start, end, name,
                                     "; ".join(rectangles))
            changed = True
        elif path == "Mesh" and name == "Circular boundaries" and value:
            circles = []
            for c in value.split(";"):
                ids, centre = c.split(":")
                circles.append(ids + ": " + ", ".join(
                    scale_number(x) for x in centre.split(",")))
            geometry = replace_entry(geometry, start, end, name,
                                     "; ".join(circles))
        elif path == "Mesh" and name == "File" and value.endswith(".geo"):
            geo = os.path.join(os.path.dirname(scene_path), value)
            geometry = replace_entry(geometry, start, end, name,
                                     "scaled.geo")
            changed = True
            geometry_files["scaled.geo"] = (
                open(geo).read() + f"\nMesh.ScalingFactor = {FACTOR};\n")
    if changed:
        yield ("geometry", f"every coordinate x {FACTOR}", geometry,
               geometry_files)


def absolute_paths(text, scene_dir):
    """Mesh/File made absolute, so that the copy runs anywhere."""
    for path, name, value, start, end in entries(text):
        if path == "Mesh" and name == "File" and value and \
                not os.path.isabs(value) and value != "scaled.geo":
            text = replace_entry(text, start, end, name,
                                 os.path.normpath(
                                     os.path.join(scene_dir, value)))
    return text


def run(program, scene_path, mutant):
    kind, description, text, files = mutant
    work = tempfile.mkdtemp(prefix="mutant-")
    try:
        text = absolute_paths(text, os.path.dirname(scene_path))
        name = os.path.basename(scene_path)
        with open(os.path.join(work, name), "w") as f:
            f.write(text)
        for file_name, content in files.items():
            with open(os.path.join(work, file_name), "w") as f:
                f.write(content)
        try:
            p = subprocess.run([program, name], cwd=work,
                               capture_output=True, text=True, timeout=300)
            code = p.returncode
            last = (p.stderr.strip().splitlines() or [""])[-1]
        except subprocess.TimeoutExpired:
            code, last = "timeout", ""
        return scene_path, kind, description, code, last
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main():
    program = os.path.abspath(sys.argv[1])
    scenes = [os.path.abspath(s) for s in sys.argv[2:]]
    jobs = []
    for scene in scenes:
        base = os.path.basename(scene)
        for mutant in mutants(scene):
            key = f"{mutant[0]}: {mutant[1]}"
            reason = next((why for scene_name, pattern, why in EXEMPT
                           if scene_name == base and re.search(pattern, key)),
                          None)
            if reason:
                print(f"exempt  {base}: {mutant[1]}: {reason}")
                continue
            jobs.append((scene, mutant))
    failures = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        results = pool.map(lambda job: run(program, *job), jobs)
        for scene, kind, description, code, last in results:
            base = os.path.basename(scene)
            if code == 2:
                print(f"killed  {base}: {description}")
            else:
                failures += 1
                verdict = "SURVIVED (checks passed)" if code == 0 else \
                    f"ERROR (exit {code}: {last})"
                print(f"{verdict}  {base}: {description}")
    print(f"{len(jobs)} mutants, {len(jobs) - failures} killed, "
          f"{failures} not")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
