#!/usr/bin/env python3
"""Contact patch tests on non-matching meshes, mortar against analytic.

Two blocks [0,1]x[0,1] (lower, E_l = 1e9, nu = 0.3) and [0,1]x[1,2] (upper,
E_u = 3e9 or 1e12, nu = 0.2), sides sliding, bottom fixed, uniform pressure
q = 1e6 Pa on top, the whole scene rotated by 0 or 30 degrees. Exact, in the
blocks' frame (x', y'): u' = (0, u_y'(y')) with
e_yy = -q (1+nu)(1-2nu)/(E(1-nu)) in each block, tau'_yy = -q,
tau'_xx = -q nu/(1-nu), tau'_xy = 0, contact pressure q; rotated to the
global frame by R(theta). Cases: mesh ratios (cells across the interface,
upper:lower) 3:7, 5:7, 7:9, 1:10 and 10:1, either side slave, both
rotations, both contrasts (40 runs).

Asserted for mortar (the default): nodal displacement, stress at every Gauss
point and contact pressure at every slave vertex equal the exact fields to
1e-10 relative, and the contact force equals the load q x 1 to 1e-8: the
program's own checks must all PASS (exit 0).
With --compare, the same cases are also run with node-to-segment and a table
of the errors of both is printed (for the README; not asserted).

Usage: mortar_patch.py PROGRAM [--compare]
"""

import math
import os
import re
import subprocess
import sys
import tempfile

Q = 1e6
E_LOWER, NU_LOWER, NU_UPPER = 1e9, 0.3, 0.2


def scene(n_upper, n_lower, slave_upper, angle, e_upper, pairing, tolerance):
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    yb = f"(-x*({s!r}) + y*({c!r}))"  # y' of a global point
    c_l = f"(1+{NU_LOWER})*(1-2*{NU_LOWER})/({E_LOWER}*(1-{NU_LOWER}))"
    c_u = f"(1+{NU_UPPER})*(1-2*{NU_UPPER})/({e_upper}*(1-{NU_UPPER}))"
    uy = (f"if({yb} < 1, -{Q}*{c_l}*{yb}, "
          f"-{Q}*{c_l} - {Q}*{c_u}*({yb} - 1))")
    a = f"if({yb} < 1, -{Q}*{NU_LOWER}/(1-{NU_LOWER}), " \
        f"-{Q}*{NU_UPPER}/(1-{NU_UPPER}))"
    b = f"-{Q}"
    sxx = f"({a})*{c*c!r} + ({b})*{s*s!r}"
    syy = f"({a})*{s*s!r} + ({b})*{c*c!r}"
    sxy = f"(({a}) - ({b}))*{s*c!r}"
    slave, master = (6, 5) if slave_upper else (5, 6)
    return f"""subsection Mesh
  set Rectangles = 0, 0, 1, 1, {n_lower}, 3, 1, 0, 1, 2, 3, 5; \\
                   0, 1, 1, 2, {n_upper}, 2, 2, 1, 1, 2, 6, 4
  set Rotation angle = {angle}
end
subsection Materials
  set Number of materials = 2
  subsection Material 0
    set Material id     = 1
    set Young's modulus = {E_LOWER}
    set Poisson's ratio = {NU_LOWER}
  end
  subsection Material 1
    set Material id     = 2
    set Young's modulus = {e_upper}
    set Poisson's ratio = {NU_UPPER}
  end
end
subsection Boundary conditions
  set Number of conditions = 3
  subsection Condition 0
    set Boundary ids = 3
    set Type         = displacement
  end
  subsection Condition 1
    set Boundary ids = 1, 2
    set Type         = sliding
  end
  subsection Condition 2
    set Boundary ids = 4
    set Type         = pressure
    set Value        = {Q}
  end
end
subsection Contact
  set Number of interfaces = 1
  subsection Interface 0
    set Name               = blocks
    set Slave boundary id  = {slave}
    set Master boundary id = {master}
    set Pairing            = {pairing}
  end
end
subsection Output
  set Terminal    = test
  set Write files = false
end
subsection Verification
  set Exact displacement = {-s!r}*({uy}); {c!r}*({uy})
  set Exact stress       = {sxx}; {syy}; {sxy}
  set Exact contact pressure = {Q}
  set Tolerance          = {tolerance}
  set Reference contact forces = blocks: {Q}
end
"""


def run(program, text):
    with tempfile.TemporaryDirectory() as work:
        path = os.path.join(work, "patch.prm")
        with open(path, "w") as f:
            f.write(text)
        p = subprocess.run([program, path], cwd=work, capture_output=True,
                           text=True, timeout=120)
    errors = {}
    for what, key in (("nodal displacement", "u"), ("stress", "stress"),
                      ("contact pressure", "p")):
        m = re.search(r"check relative " + what + r" error: (\S+)", p.stdout)
        errors[key] = float(m.group(1)) if m else float("nan")
    return p.returncode, errors, (p.stderr.strip().splitlines() or [""])[-1]


def main():
    program = os.path.abspath(sys.argv[1])
    compare = "--compare" in sys.argv[2:]
    failures = 0
    cases = [(3, 7), (5, 7), (7, 9), (1, 10), (10, 1)]
    if compare:
        print("| upper:lower cells | slave | angle | E_u/E_l | mortar u, "
              "stress, p | node-to-segment u, stress, p |")
        print("|---|---|---|---|---|---|")
    for n_upper, n_lower in cases:
        for slave_upper in (True, False):
            for angle in (0, 30):
                for e_upper in (3e9, 1e12):
                    code, err, last = run(program, scene(
                        n_upper, n_lower, slave_upper, angle, e_upper,
                        "mortar", 1e-10))
                    label = (f"{n_upper}:{n_lower}, slave "
                             f"{'upper' if slave_upper else 'lower'}, "
                             f"{angle} deg, contrast {e_upper / E_LOWER:g}")
                    ok = code == 0
                    failures += 0 if ok else 1
                    if compare:
                        _, nts, _ = run(program, scene(
                            n_upper, n_lower, slave_upper, angle, e_upper,
                            "node-to-segment", 1e300))
                        print(f"| {n_upper}:{n_lower} | "
                              f"{'upper' if slave_upper else 'lower'} | "
                              f"{angle} | {e_upper / E_LOWER:g} | "
                              f"{err['u']:.1e}, {err['stress']:.1e}, "
                              f"{err['p']:.1e} | {nts['u']:.1e}, "
                              f"{nts['stress']:.1e}, {nts['p']:.1e} |")
                    else:
                        print(f"{'PASS' if ok else 'FAIL'}: {label}: "
                              f"u {err['u']:.1e}, stress {err['stress']:.1e}, "
                              f"pressure {err['p']:.1e}"
                              + ("" if ok else f" (exit {code}: {last})"))
    print(f"{failures} of {len(cases) * 8} cases failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
