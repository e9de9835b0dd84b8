#!/usr/bin/python3
"""Coulomb friction in 3D against independent references, one load step.

1. mu = 0 reproduces the frictionless results: the 3D contact patch tests
   (hexahedra, node-to-segment and mortar; tetrahedra) and the small Hertz
   sphere are run as they are and with Friction = coulomb, Friction
   coefficient = 0 on every interface (both on the sparse path): every
   number of summary.json agrees to 1e-12 relative to the largest of its
   kind (the friction rows change the factorisation's ordering: round-off).
2. A very large mu reproduces the bonded solution on matching meshes: two
   unit cubes (2 cells a side each, tests/meshes/contact_stack_3d.geo, the
   lower one's bottom held) with mu = 1e3 under a traction
   (5e4, 2.5e4, -1e6) Pa on the top (no edge lifts), node-to-node pairing (every pair
   sticks), against the box of tests/meshes/block.geo with the same two
   materials sharing the interface's nodes: energy, max |u| and the
   reaction to 1e-10.
3. Statics of the upper cube held by friction only (its sides free), a
   tangential load skew to every mesh axis (angle 0.3 rad from x, ratio
   r = 0.2 of the normal load), non-matching meshes (4 cells a side below,
   3 above): with mu = 0.5 > r the interface force on the slave balances
   the load to 1e-8 relative (node-to-segment and mortar), and
   summary.json's stick_area + slip_area is its contact_area to 1e-12;
   with
   mu = 0.1 < r the run is refused in one line naming the ratio 0.2.
4. The same on a tilted interface: the stack rotated by 0.7 rad about the
   skew axis (1, 2, 3) with the load rotated along (a tangential ratio
   0.8 mu and 1.2 mu in the interface's frame, mu = 0.3): below, the
   interface force balances the load to 1e-8; above, one line refuses it
   naming the ratio 1.2 x 0.3 = 0.36.
5. The tilted held case with pictures on: pressure_block.png and
   friction_block.png (the stick/slip map) are written.
6. A load path with a small step: prm/tibial_tray_3d_friction.prm (the
   tray and insert held on the bone by friction alone, five cases, the
   last 1.2 % below the fourth): every case converges in at most 20
   iterations, and the interface force on the tray balances the load on
   the insert to 1e-8 relative (statics). Its last case took 50
   iterations without converging while a slipping pair's next direction
   was its slip's own (1e-10 of the displacements at the stick/slip
   boundary).
Each held case runs on the automatic path (condensed: the semismooth Newton
step's springs in its dense multiplier system, 9-10 iterations), on the
sparse one (the springs in each iteration's CHOLMOD factor), on step-41's
(UMFPACK on the whole condensed system, the springs added before the
condensation) and on the iterative one (the springs applied in CG with
AMG, those as stiff as the matrix held as rows, which must happen at least
once); their energy and max |u| agree to 1e-8. The condensed and sparse
paths take the Newton step on the Coulomb bound too (the slipping pairs'
force mu lambda_n d with the lambda_n being solved for: a column of the
condensed path's dense multiplier system, GMRES preconditioned by the
sparse factor, GMRES with AMG on the iterative path, every path at least
one such solve), so they take the same number of iterations (the same
Newton loop on exact solves), no more than step-41's, which keeps the
bound of the last solve (a fixed point). The sparse path solves a system
whose active set is its factor's but whose springs are new by CG (GMRES
with couplings) on that factor: the held cases must take that branch at
least once.
Usage: friction_3d.py KNEE_CONTACT
"""
import json
import math
import os
import re
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
MESHES = os.path.join(HERE, "..", "meshes")
sys.path.insert(0, HERE)
from friction import (MATERIALS, compare, kind_of, mu_zero_runs,  # noqa
                      run_scene)

FRICTIONLESS = [("contact_patch_3d_hex.prm", 1e-12),
                ("contact_patch_3d_tet.prm", 1e-12),
                ("contact_patch_3d_matching.prm", 1e-12),
                ("hertz_sphere_3d_small.prm", 1e-12)]


# The stack: boundary ids 3 bottom, 4 top, 5 top of the lower cube, 6
# bottom of the upper one.
STACK = """
subsection Mesh
  set Source         = file
  set File           = {mesh}
  set Gmsh arguments = -setnumber n_lower {lower} -setnumber n_upper {upper} \\
                       -setnumber angle {angle}
end
{materials}subsection Boundary conditions
  set Number of conditions = 2
  subsection Condition 0
    set Boundary ids = {bottom}
    set Type         = displacement
  end
  subsection Condition 1
    set Boundary ids = {top}
    set Type         = traction
    set Value        = {tx!r}; {ty!r}; {tz!r}
  end
end
subsection Contact
  set Maximum active set iterations = 100
  set Solver = {solver}
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
    set Slave boundary id    = 6
    set Master boundary id   = 5
    set Pairing              = {pairing}
    set Friction             = coulomb
    set Friction coefficient = {mu}
  end"""


def run(binary, text, folder, name, expect_success=True):
    """run_scene(); its summary.json if it must succeed, else the run."""
    result = run_scene(binary, text, folder, name, expect_success)
    if not expect_success:
        return result
    with open(os.path.join(folder, name, "summary.json")) as f:
        summary = json.load(f)
    summary["stdout"] = result.stdout
    return summary


def rotation(angle):
    """Rodrigues' rotation about (1, 2, 3) / sqrt(14), as the .geo has it."""
    a = [1 / math.sqrt(14), 2 / math.sqrt(14), 3 / math.sqrt(14)]
    c, s = math.cos(angle), math.sin(angle)
    cross = [[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]]
    return [[c * (i == j) + s * cross[i][j] + (1 - c) * a[i] * a[j]
             for j in range(3)] for i in range(3)]


def stack(load, folder, name, pairing="mortar", mu=0.5, lower=4, upper=3,
          angle=0.0, n_interfaces=1, solver="automatic"):
    tx, ty, tz = load
    return STACK.format(
        mesh=os.path.join(MESHES, "contact_stack_3d.geo"), lower=lower,
        upper=upper, angle=angle, materials=MATERIALS, bottom=3, top=4,
        tx=tx, ty=ty, tz=tz, n_interfaces=n_interfaces, solver=solver,
        interface=INTERFACE.format(pairing=pairing, mu=mu)
        if n_interfaces else "",
        folder=os.path.join(folder, name))


def balance(summary, load):
    """|force on the slave + load|_inf / |load|_inf."""
    interface = summary["contact_interfaces"]["block"]
    total = [interface["force_on_slave"][d] +
             interface["tangential_force_on_slave"][d] + load[d]
             for d in range(3)]
    return max(abs(x) for x in total) / max(abs(x) for x in load), interface


def iterations(summary):
    found = re.findall(r"friction iteration\s+(\d+)", summary["stdout"])
    return int(found[-1]) if found else 0


def main():
    binary = os.path.abspath(sys.argv[1])
    failures = 0
    # The sparse path's solves on a factor made with other springs (CG on
    # the last factor where the active set stayed): they must have been
    # taken, so that the comparison above covers them.
    stale_solves = 0
    # The iterative path's springs held as rows (springs::tie_stiff()):
    # they must have been taken, so that its comparison with the sparse
    # path covers them.
    tied_springs = 0
    recomputed = 0
    with tempfile.TemporaryDirectory() as folder:
        # 1. mu = 0.
        for name, tolerance, plain, other in mu_zero_runs(
                binary, folder, FRICTIONLESS, run):
            del plain["stdout"], other["stdout"]
            failures += compare(name + ", mu = 0", plain, other, tolerance,
                                kind_of)

        # 2. Very large mu against the bonded box.
        load = (5e4, 2.5e4, -1e6)
        bonded_text = stack(load, folder, "bonded", n_interfaces=0)
        bonded_text = re.sub(
            r"set File .*\n.*\n.*\n",
            "set File = %s\n  set Gmsh arguments = -setnumber hex 1 "
            "-setnumber n 2 -setnumber two 1\n"
            % os.path.join(MESHES, "block.geo"), bonded_text)
        # block.geo's bottom and top are 5 and 6.
        bonded_text = bonded_text.replace("Boundary ids = 3", "Boundary ids "
                                          "= 5").replace("Boundary ids = 4",
                                                         "Boundary ids = 6")
        bonded = run(binary, bonded_text, folder, "bonded")
        sticking = run(binary, stack(load, folder, "sticking",
                                     pairing="node-to-node", mu=1e3,
                                     lower=2, upper=2), folder, "sticking")
        assert sticking["contact_interfaces"]["block"]["n_slip"] == 0
        for key in ("energy", "max_displacement"):
            error = abs(sticking[key] - bonded[key]) / abs(bonded[key])
            print("mu = 1e3 against bonded: %s %.1e (tolerance 1e-10)"
                  % (key, error))
            failures += error > 1e-10
        reaction = sticking["reactions"]["3"]
        reference = bonded["reactions"]["5"]
        reaction = reaction if isinstance(reaction, list) else \
            reaction["force"]
        reference = reference if isinstance(reference, list) else \
            reference["force"]
        error = max(abs(x - y) for x, y in zip(reaction, reference)) / \
            max(abs(x) for x in reference)
        print("mu = 1e3 against bonded: reaction %.1e (tolerance 1e-10)"
              % error)
        failures += error > 1e-10

        # 3. and 4. Statics of the upper cube held by friction, the stack
        # level and tilted.
        G, r, skew = 1e6, 0.2, 0.3
        for angle, mu, ratios in ((0.0, 0.5, (r,)),
                                  (0.7, 0.3, (0.8 * 0.3, 1.2 * 0.3))):
            R = rotation(angle)
            for ratio in ratios:
                local = (ratio * G * math.cos(skew), ratio * G * math.sin(skew),
                         -G)
                load = tuple(sum(R[i][j] * local[j] for j in range(3))
                             for i in range(3))
                for pairing in ("node-to-segment", "mortar"):
                    name = "statics_%g_%g_%s" % (angle, ratio, pairing)
                    if ratio < mu:
                        # The automatic path (condensed), the sparse one,
                        # step-41's and the iterative one, each with the
                        # Newton step's springs in its own algebra, must
                        # agree.
                        found = {}
                        for solver in ("automatic", "sparse", "step-41",
                                       "iterative"):
                            summary = run(binary, stack(
                                load, folder, name + solver, pairing=pairing,
                                mu=mu, angle=angle, solver=solver), folder,
                                name + solver)
                            error, interface = balance(summary, load)
                            found[solver] = summary
                            print("angle %g, %s, mu = %g > %.3f, %s (%s): "
                                  "interface force + load relative %.1e "
                                  "(tolerance 1e-8); %d sticking, %d "
                                  "slipping, %d iterations"
                                  % (angle, pairing, mu, ratio, solver,
                                     summary["solver"]["name"], error,
                                     interface["n_stick"], interface["n_slip"],
                                     iterations(summary)))
                            failures += error > 1e-8
                            # The sticking and slipping areas make up the
                            # contact area (every active pair is one).
                            shares = (interface["stick_area"] +
                                      interface["slip_area"])
                            if abs(shares - interface["contact_area"]) > \
                                    1e-12 * interface["contact_area"]:
                                print("  stick + slip area %.17g, contact "
                                      "area %.17g" % (
                                          shares, interface["contact_area"]))
                                failures += 1
                        difference = max(
                            abs(found[other][key] -
                                found["sparse"][key]) / abs(
                                found["sparse"][key])
                            for key in ("energy", "max_displacement")
                            for other in ("automatic", "step-41",
                                          "iterative"))
                        print("  the four paths' energy and max |u| differ "
                              "by %.1e (tolerance 1e-8)" % difference)
                        failures += difference > 1e-8
                        stale_solves += found["sparse"]["solver"][
                            "stale_factor_solves"]
                        tied_springs += found["iterative"]["solver"][
                            "tied_springs"]
                        recomputed += found["iterative"]["solver"][
                            "amg_recomputed"]
                        # The condensed and sparse paths take the Newton
                        # step on the bound (ContactSystem::
                        # set_bound_couplings: the dense multiplier system,
                        # GMRES on the sparse factor) on exact solves: the
                        # same iterations, no more than step-41's fixed
                        # point on the bound mu lambda_n. (The iterative
                        # path's solves are inexact while the sets change.)
                        newton = set(iterations(found[solver])
                                     for solver in ("sparse", "automatic"))
                        fixed_point = iterations(found["step-41"])
                        if found["automatic"]["solver"]["name"] != \
                                "condensed" or len(newton) != 1 or \
                                max(newton) > fixed_point:
                            print("  the Newton step took %s iterations "
                                  "(condensed, sparse), the fixed point %d"
                                  % (sorted(newton), fixed_point))
                            failures += 1
                        for solver in ("automatic", "sparse", "iterative"):
                            if found[solver]["solver"]["coupled_solves"] \
                                    == 0:
                                print("  %s: no coupled solve" % solver)
                                failures += 1
                    # Below the ratio (the level stack at mu = 0.1, the
                    # tilted one at 1.03 mu): refused, naming it.
                    weak = 0.1 if angle == 0 else mu
                    if ratio < weak:
                        continue
                    refused = run(binary, stack(
                        load, folder, name + "_slides", pairing=pairing,
                        mu=weak, angle=angle), folder, name + "_slides",
                        expect_success=False)
                    lines = refused.stderr.strip().splitlines()
                    named = "tangential/normal force %.3g)" % ratio
                    ok = (refused.returncode == 1 and len(lines) == 1 and
                          "friction cannot hold it" in lines[0] and
                          named in lines[0])
                    print("angle %g, %s, mu = %g < %.3f: exit %d, %s (%s)" %
                          (angle, pairing, weak, ratio, refused.returncode,
                           "names the ratio" if ok else "WRONG",
                           lines[-1] if lines else ""))
                    failures += not ok
        print("the sparse path solved %d systems by CG or GMRES on a factor "
              "with other springs (must be > 0)" % stale_solves)
        failures += stale_solves == 0
        print("the iterative path held %d springs as rows (must be > 0)"
              % tied_springs)
        failures += tied_springs == 0
        # The agreement above holds for hierarchies ML recomputed on an
        # earlier set's aggregates (IterativeContactSystem::build_amg()).
        print("the iterative path recomputed %d hierarchies on earlier "
              "aggregates (must be > 0)" % recomputed)
        failures += recomputed == 0
        # 5. The pictures of a frictional 3D interface: the pressure map
        # and the stick/slip map (scripts/plot_results_3d.py) are written.
        R = rotation(0.7)
        local = (0.24 * G * math.cos(skew), 0.24 * G * math.sin(skew), -G)
        load = tuple(sum(R[i][j] * local[j] for j in range(3))
                     for i in range(3))
        text = stack(load, folder, "pictures", mu=0.3, angle=0.7).replace(
            "set Pictures = false", "set Pictures = true")
        run(binary, text, folder, "pictures")
        for picture in ("pressure_block.png", "friction_block.png"):
            path = os.path.join(folder, "pictures", picture)
            ok = os.path.exists(path) and os.path.getsize(path) > 0
            print("picture %s: %s" % (picture, "written" if ok else "MISSING"))
            failures += not ok
        # 6. The tray's load path.
        prm = os.path.join(HERE, "..", "..", "prm")
        with open(os.path.join(prm, "tibial_tray_3d_friction.prm")) as f:
            text = f.read()
        text = text.replace("set File           = tibial_tray_3d.geo",
                            "set File           = " + os.path.join(
                                prm, "tibial_tray_3d.geo"))
        text += ("subsection Output\n  set Folder = %s\n  set Pictures = "
                 "false\nend\n" % os.path.join(folder, "tray"))
        run_scene(binary, text, folder, "tray")
        for case in range(5):
            with open(os.path.join(folder, "tray", "case_%03d" % case,
                                   "summary.json")) as f:
                summary = json.load(f)
            tray = summary["contact_interfaces"]["tray"]
            load = summary["applied_load"]
            total = [load[d] + tray["force_on_slave"][d] +
                     tray["tangential_force_on_slave"][d] for d in range(3)]
            error = max(abs(x) for x in total) / max(abs(x) for x in load)
            ok = (summary["converged"] and
                  summary["active_set_iterations"] <= 20 and error <= 1e-8)
            print("tray path, case %d: %s in %d iterations (at most 20), "
                  "interface force + load relative %.1e (tolerance 1e-8)" %
                  (case, "converged" if summary["converged"] else
                   "NOT converged", summary["active_set_iterations"], error))
            failures += not ok
    print("PASS" if failures == 0 else "FAIL: %d checks" % failures)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
