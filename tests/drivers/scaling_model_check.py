#!/usr/bin/python3
"""scripts/scaling_model.py's arithmetic against runs made by a known model.

Runs on 1 and 2 ranks are written from chosen constants with the model's
own equations, written out here again (not by calling predict()); fit()
must give the constants back, predict() the N = 4 run on 2 cores to
1e-12, and extrapolate() the measured costs per DoF unchanged at the
measured size on one rank (no network term but its latency). A sign or a
factor of 2 wrong anywhere fails. The model of the distributed
mesh (fit_distributed(), predict_distributed(), extrapolate_distributed())
the same way. Speed itself is measured by parallel_scaling.py --model,
never in a test.
Usage: scaling_model_check.py
"""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "..", "scripts"))
import scaling_model  # noqa: E402

TOLERANCE = 1e-12
CONSTANTS = {"R1": 20.0, "beta": 1.2, "k1": 0.05, "c2": 0.01, "A1": 1.5,
             "a2": 0.3, "W1": 2.0, "I1": 300.0, "M_replicated": 800.0,
             "P_replicated": 150.0, "P_divided": 200.0, "dofs": 2.0e5}


def synthetic(ranks, cores):
    """A run on @p ranks of @p cores, by the module text's equations."""
    c = CONSTANTS
    occupancy = max(1.0, ranks / cores)
    busy = min(ranks, cores)
    krylov = c["I1"] * (c["k1"] / busy + c["c2"] * math.log2(ranks))
    amg = c["A1"] / busy + c["a2"] * math.log2(ranks)
    replicated = c["R1"] * (c["beta"] if ranks > 1 else 1.0) * occupancy
    path = c["P_replicated"] + c["P_divided"] / ranks
    return {"ranks": ranks, "dofs": c["dofs"], "cg": c["I1"],
            "krylov": krylov, "amg": amg, "output": c["W1"],
            "run": replicated + krylov + amg + c["W1"],
            "path_measured": path, "peak": c["M_replicated"] + path}

DISTRIBUTED = {"G1": 12.0, "P2": 3.0, "Q2": 1.4, "H1": 8.0, "D1": 40.0,
               "beta_D": 1.3, "k1": 0.05, "c2": 0.01, "A1": 1.5, "a2": 0.3,
               "W1": 2.0, "I1": 300.0, "I2": 240.0, "M_mesh": 900.0,
               "M_replicated": 400.0, "M_divided": 1000.0, "M0": 150.0,
               "dofs": 2.0e5}


def synthetic_distributed(ranks, cores):
    """A run on the distributed mesh, by the module text's equations."""
    c = DISTRIBUTED
    busy = min(ranks, cores)
    several = ranks > 1
    cg = c["I2"] if several else c["I1"]
    krylov = cg * (c["k1"] / busy + c["c2"] * math.log2(ranks))
    amg = c["A1"] / busy + c["a2"] * math.log2(ranks)
    partition = c["P2"] if several else 0.0
    descriptions = c["Q2"] if several else 0.0
    part = c["H1"] / busy if several else 0.0
    mesh = c["G1"] + partition + descriptions + part
    rest = c["D1"] * (c["beta_D"] if several else 1.0) / busy
    spread = c["M_replicated"] + c["M_divided"] / ranks
    return {"ranks": ranks, "dofs": c["dofs"], "cg": cg,
            "krylov": krylov, "amg": amg, "output": c["W1"], "mesh": mesh,
            "partition": partition, "descriptions": descriptions,
            "part": part, "mesh_peak": c["M_mesh"] if several else 0.0,
            "run": mesh + rest + krylov + amg + c["W1"],
            "peak": max(c["M_mesh"], spread) if several else spread}


def check_distributed(check):
    """fit_distributed() gives the constants back, predict_distributed()
    the runs on 1, 2, 4 and 8 ranks of 2 cores; the extrapolation's terms
    at the measured size on one rank and their growth with the ranks."""
    model = scaling_model.fit_distributed(synthetic_distributed(1, 2),
                                          synthetic_distributed(2, 2),
                                          DISTRIBUTED["M0"])
    for key, value in DISTRIBUTED.items():
        check("distributed fit " + key, model[key], value)
    for ranks in (1, 2, 4, 8):
        run = synthetic_distributed(ranks, 2)
        prediction = scaling_model.predict_distributed(model, ranks, 2)
        check("distributed run on %d ranks" % ranks, prediction["run"],
              run["run"])
        check("distributed memory on %d ranks" % ranks,
              prediction["memory"], run["peak"])
    c = DISTRIBUTED
    network = {"latency_s": 1e-6, "bandwidth_Bps": 1e30}
    latency = (4 * scaling_model.LEVELS + 1) * scaling_model.NEIGHBOURS * 1e-6
    # (The distributed path's iterations: the two-rank run's.)
    solve = c["A1"] + c["I2"] * (c["k1"] + 2 * c["c2"] + latency)
    e = scaling_model.extrapolate_distributed(model, 0.4, c["dofs"], 1, 0.0,
                                              network)
    serial = c["G1"] + c["P2"] + c["Q2"] + c["W1"]
    check("distributed serial at the size", e["now"]["serial"], serial)
    check("distributed run at the size", e["now"]["run"],
          serial + c["H1"] + c["D1"] * c["beta_D"] + solve)
    # Ten times the DoFs on ten ranks: the serial part grows 10 x (the
    # descriptions too: one pass whatever the ranks); the mesh read in
    # parts keeps its memory per rank.
    e10 = scaling_model.extrapolate_distributed(model, 0.4, 10 * c["dofs"],
                                                10, 0.0, network)
    check("distributed serial, 10 x on 10", e10["now"]["serial"],
          10 * (c["G1"] + c["P2"] + c["Q2"] + c["W1"]))
    # (M0, the program's own, does not grow.)
    check("rank 0's memory, 10 x on 10", e10["now"]["memory"],
          c["M0"] + 10 * max(c["M_mesh"] - c["M0"],
                             c["M_replicated"] - c["M0"] +
                             c["M_divided"] / 10))
    check("memory in parts, 10 x on 10", e10["parts"]["memory"],
          e["parts"]["memory"])


def main():
    failures = []

    def check(name, value, expected):
        error = abs(value - expected) / max(abs(expected), 1e-300)
        print("%-32s %.6g against %.6g: %s" % (
            name, value, expected, "PASS" if error <= TOLERANCE else "FAIL"))
        if error > TOLERANCE:
            failures.append(name)

    model = scaling_model.fit(synthetic(1, 2), synthetic(2, 2))
    for key, value in CONSTANTS.items():
        check("fit " + key, model[key], value)
    for ranks in (1, 2, 4, 8):
        run = synthetic(ranks, 2)
        prediction = scaling_model.predict(model, ranks, 2)
        check("run on %d ranks" % ranks, prediction["run"], run["run"])
        check("memory on %d ranks" % ranks, prediction["memory"], run["peak"])
    # At the measured size on one rank the stage is the one-rank run at the
    # two-rank rate (beta, k1 + 2 c2), plus the network's latency.
    network = {"latency_s": 1e-6, "bandwidth_Bps": 1e30}
    e = scaling_model.extrapolate(model, 0.4, CONSTANTS["dofs"], 1, 0.0,
                                  network)
    c = CONSTANTS
    latency = (4 * scaling_model.LEVELS + 1) * scaling_model.NEIGHBOURS * 1e-6
    expected = (c["R1"] * c["beta"] + c["W1"] + c["A1"] +
                c["I1"] * (c["k1"] + 2 * c["c2"] + latency))
    check("extrapolation at the size", e["stage"]["run"], expected)
    check("distributed stage on 1 rank", e["distributed"]["run"], expected)
    check("memory at the size", e["stage"]["memory"],
          c["M_replicated"] + c["P_replicated"] + c["P_divided"])
    # Ten times the DoFs on ten ranks: the distributed stage's memory per
    # rank stays, its CG iterations grow by 10^alpha.
    e10 = scaling_model.extrapolate(model, 0.4, 10 * CONSTANTS["dofs"], 10,
                                    0.0, network)
    check("distributed memory, 10 x on 10", e10["distributed"]["memory"],
          e["distributed"]["memory"])
    check("CG iterations, 10 x", e10["cg"], c["I1"] * 10 ** 0.4)
    check_distributed(check)
    if failures:
        sys.exit("FAILED: " + ", ".join(failures))


if __name__ == "__main__":
    main()
