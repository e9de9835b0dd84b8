#!/usr/bin/python3
"""A scaling model of knee_contact under mpirun, from measured per-rank costs.

Used by parallel_scaling.py --model (which runs the scene and passes the
runs' numbers in); the arithmetic is here so that tests/unit can check it
on numbers made by a known model (tests/drivers/scaling_model_check.py).

A run is split into what its summary.json times (rank 0):

  K  the Krylov iterations of the iterative path (distributed),
  A  the AMG set-up (distributed),
  W  the work of rank 0 alone, while the others wait: the output, and
     gmsh with the mesh checks (the run's wall time less its timers),
  R  everything else: reading the mesh, DoFs, assembly, contact search,
     the active-set loop's replicated decisions, the error bars' strain
     recovery (replicated on every rank in this stage of issue 38).

On a machine of C cores with N ranks (o = max(1, N / C) ranks per core):

  R(N) = R1 * beta * o               beta: two ranks sharing the memory
                                     bandwidth (measured at N = 2), 1 at N = 1
  K(N) = I * (k1 / min(N, C) + c2 * log2 N)
                                     k1: time per CG iteration on one rank,
                                     c2: the excess per iteration at N = 2
                                     (halo exchanges, reductions, the
                                     constraints' ghosts, bandwidth), taken
                                     to grow as the depth of a reduction tree
  A(N) = A1 / min(N, C) + a2 * log2 N
  W(N) = W1
  I    = I1 (ML aggregates within each rank; the METIS partition keeps
         the iterations of one rank: an assumption the N = 4 run checks)

Memory per rank: the replicated part (the peak of one rank less its
iterative path) plus the path's replicated vectors and its divided matrix
and hierarchy, P(N) = Pr + Pd / N (Pr, Pd from N = 1, 2).

On the distributed mesh (a run whose summary.json says
solver/distributed_mesh = 1: the iterative path over several ranks, a
uniform sequence) every rank works on its own cells and the run splits
into (fit_distributed(), predict_distributed(); rank 0's times):

  G  rank 0 alone makes and checks the whole mesh (summary's "mesh: read";
     one process's whole mesh phase): serial, G(N) = G1,
  P  rank 0's METIS partition ("mesh: partition"): P(N) = P2,
  Q  rank 0 makes and sends every rank's description ("mesh: descriptions"):
     one pass over the whole mesh finds each rank's cells, each
     description is made from its own (since 2026-12-02 night; deal.II's
     made each with passes over the whole mesh, N q): Q(N) = Q2, the
     whole mesh once whatever the ranks,
  H  a rank makes its cells from its description ("mesh: part"):
     H(N) = 2 H2 / min(N, C) (ranks sharing a core take turns),
  D  the rest of the timed work, on each rank's cells (setup, assembly,
     the active-set loop's condensation and decisions, postprocess, error
     estimate): D(N) = D1 beta_D / min(N, C), beta_D = 2 D(2) / D1,
  K, A, W as above, but with I = I2 for N > 1: the CG iterations of the
     two-rank run, since N > 1 ranks solve another operator than one
     process (the condensed rows on each rank's part, its own aggregates,
     against one process's whole matrix): the 3D knee at 1e6 DoFs took
     482 iterations on one process, 360 on two and 337 on four
     (2026-12-02); I1 stays one process's,
  memory of rank 0 = max(M_mesh, Mr + Md / N): M_mesh its peak while it
     holds the whole mesh and a description (summary's
     solver/mesh_peak_memory_MB at N = 2, taken constant in N), Mr, Md
     from the peaks at N = 1, 2. Of each, M0 (the program and its
     libraries: the peak of a scene of a few cells) does not grow with the
     DoFs, the rest grows as n in the extrapolation.

For 1e7 and 1e8 DoFs on 16-256 ranks (no cluster is reachable here) the
same costs per DoF are extrapolated twice: for this stage (the mesh, the
stiffness matrix and the replicated work on every rank) and for the
distributed stage the issue asks for (every term divided, the master
surface gathered), with the network's latency and bandwidth assumed
(ASSUMED_NETWORK) and the CG iterations growing as n^alpha (alpha from
two sizes measured in the same invocation).
"""
import math

# An InfiniBand EDR-class cluster: the latency of a small message and the
# bandwidth of one rank's link (assumed, not measured here).
ASSUMED_NETWORK = {"latency_s": 2e-6, "bandwidth_Bps": 10e9}
# Per CG iteration of the distributed stage: two reductions (CG's inner
# products), and an AMG V-cycle of LEVELS levels with a halo exchange per
# smoothing sweep and residual (4 a level) with NEIGHBOURS ranks each, plus
# the operator's own halo exchange.
LEVELS = 4
NEIGHBOURS = 12
# Bytes of a halo: 3 doubles per vertex on the surface of a rank's part
# (6 faces of a cube of n / N / 3 vertices).
HALO_BYTES_PER_VERTEX = 3 * 8
# Bytes per master-surface face gathered (3 vertices: coordinates, dofs,
# normal).
FACE_BYTES = 3 * (3 * 8 + 3 * 8 + 3 * 8)


def replicated(run):
    """R of a run (see the module's text)."""
    return run["run"] - run["krylov"] - run["amg"] - run["output"]


def fit(one, two):
    """The model's constants from a run on one rank and one on two."""
    r1 = replicated(one)
    k1 = one["krylov"] / one["cg"]
    path_two = two["path_measured"]
    path_one = one["path_measured"]
    divided = 2 * (path_one - path_two)
    return {
        "R1": r1,
        "beta": replicated(two) / r1,
        "k1": k1,
        "c2": two["krylov"] / two["cg"] - k1 / 2,
        "A1": one["amg"],
        "a2": two["amg"] - one["amg"] / 2,
        "W1": one["output"],
        "I1": one["cg"],
        "M_replicated": one["peak"] - path_one,
        "P_replicated": path_one - divided,
        "P_divided": divided,
        "dofs": one["dofs"],
    }


def predict(model, ranks, cores, iterations=None):
    """Time [s] and memory per rank [MB] of N ranks on this machine.

    iterations: the CG iterations to assume (default the one-rank run's).
    """
    occupancy = max(1.0, ranks / cores)
    busy = min(ranks, cores)
    depth = math.log2(ranks)
    cg = model["I1"] if iterations is None else iterations
    terms = {
        "R": model["R1"] * (model["beta"] if ranks > 1 else 1.0) * occupancy,
        "K": cg * (model["k1"] / busy + model["c2"] * depth),
        "A": model["A1"] / busy + model["a2"] * depth,
        "W": model["W1"],
    }
    terms["run"] = terms["R"] + terms["K"] + terms["A"] + terms["W"]
    path = model["P_replicated"] + model["P_divided"] / ranks
    terms["path_memory"] = path
    terms["memory"] = model["M_replicated"] + path
    return terms


def iteration_exponent(small, large):
    """alpha of I ~ n^alpha from two sizes on one rank."""
    return (math.log(large["cg"] / small["cg"]) /
            math.log(large["dofs"] / small["dofs"]))


def _solve_at(model, alpha, dofs, ranks, contact_faces_ref, network,
              iterations="I1"):
    """What both extrapolations share at @p dofs on @p ranks (one per
    core): the scale n / n_measured, the CG iterations (model[@p
    iterations], growing as n^alpha), the contact faces (as n^(2/3)), the
    divided solve with the network's latency and halos per iteration, and
    the master surface's gather."""
    scale = dofs / model["dofs"]
    cg = model[iterations] * scale ** alpha
    faces = contact_faces_ref * scale ** (2. / 3.)
    depth = math.log2(ranks)
    own = dofs / ranks
    halo = 6 * (own / 3) ** (2. / 3.) * HALO_BYTES_PER_VERTEX
    per_iteration_network = (
        network["latency_s"] * (2 * depth + (4 * LEVELS + 1) * NEIGHBOURS) +
        (4 * LEVELS + 1) * halo / network["bandwidth_Bps"])
    # The work per iteration at the rate of two ranks sharing one
    # machine's memory bandwidth (the N = 2 run: a cluster's node shares
    # it among its cores too); its excess per iteration taken as the
    # network's above, since on a cluster the ranks do not share one
    # machine's bandwidth.
    work = (model["k1"] + 2 * model["c2"]) * scale / ranks
    solve = cg * (work + per_iteration_network) + \
        model["A1"] * scale / ranks
    gather = faces * FACE_BYTES / network["bandwidth_Bps"] + \
        network["latency_s"] * depth
    return scale, cg, faces, solve, gather


def extrapolate(model, alpha, dofs, ranks, contact_faces_ref,
                network=ASSUMED_NETWORK):
    """Time [s] and memory per rank [MB] at @p dofs on @p ranks (one per
    core), for this stage and for the distributed one.

    Each cost per DoF is the one measured at model["dofs"]; the CG
    iterations grow as n^alpha, the contact faces as n^(2/3).
    """
    scale, cg, faces, solve, gather = _solve_at(
        model, alpha, dofs, ranks, contact_faces_ref, network)
    # This stage: R, W and the replicated memory grow with n and do not
    # divide (R at two ranks' rate on one memory bus); the solve divides.
    replicated_work = model["R1"] * model["beta"] * scale
    stage = {
        "run": replicated_work + solve + model["W1"] * scale,
        "memory": (model["M_replicated"] + model["P_replicated"]) * scale +
        model["P_divided"] * scale / ranks,
    }
    distributed = {
        # R divides; W becomes one piece per rank (.pvtu).
        "run": (replicated_work + model["W1"] * scale) / ranks + solve +
        gather,
        "memory": (model["M_replicated"] + model["P_replicated"] +
                   model["P_divided"]) * scale / ranks +
        faces * FACE_BYTES / 2**20,
    }
    return {"stage": stage, "distributed": distributed, "cg": cg}


def divided(run):
    """D of a run on the distributed mesh: its timed work on its own cells
    (the run less the mesh phase, the Krylov iterations, the AMG set-up
    and rank 0's work alone)."""
    return run["run"] - run["mesh"] - run["krylov"] - run["amg"] - \
        run["output"]


def fit_distributed(one, two, base=0.0):
    """The distributed mesh's constants from one process and two ranks;
    @p base the peak [MB] of a scene of a few cells (M0)."""
    k1 = one["krylov"] / one["cg"]
    divided_memory = 2 * (one["peak"] - two["peak"])
    return {
        "G1": one["mesh"],
        "P2": two["partition"],
        "Q2": two["descriptions"],
        "H1": 2 * two["part"],
        "D1": divided(one),
        "beta_D": 2 * divided(two) / divided(one),
        "k1": k1,
        "c2": two["krylov"] / two["cg"] - k1 / 2,
        "A1": one["amg"],
        "a2": two["amg"] - one["amg"] / 2,
        "W1": one["output"],
        "I1": one["cg"],
        "I2": two["cg"],
        "M_mesh": two["mesh_peak"],
        "M_replicated": one["peak"] - divided_memory,
        "M_divided": divided_memory,
        "M0": base,
        "dofs": one["dofs"],
    }


def predict_distributed(model, ranks, cores, iterations=None):
    """Time [s] and rank 0's memory [MB] of N ranks on the distributed
    mesh on this machine (N = 1: one process, the whole mesh); @p
    iterations the CG iterations to assume (default I1 on one rank, the
    two-rank run's I2 on more)."""
    busy = min(ranks, cores)
    depth = math.log2(ranks)
    several = ranks > 1
    cg = model["I2" if several else "I1"] if iterations is None else \
        iterations
    terms = {
        "G": model["G1"],
        "P": model["P2"] if several else 0.0,
        "Q": model["Q2"] if several else 0.0,
        "H": model["H1"] / busy if several else 0.0,
        "D": model["D1"] * (model["beta_D"] if several else 1.0) / busy,
        "K": cg * (model["k1"] / busy + model["c2"] * depth),
        "A": model["A1"] / busy + model["a2"] * depth,
        "W": model["W1"],
    }
    terms["mesh"] = terms["G"] + terms["P"] + terms["Q"] + terms["H"]
    terms["run"] = terms["mesh"] + terms["D"] + terms["K"] + terms["A"] + \
        terms["W"]
    spread = model["M_replicated"] + model["M_divided"] / ranks
    terms["memory"] = max(model["M_mesh"], spread) if several else \
        model["M_replicated"] + model["M_divided"]
    return terms


def extrapolate_distributed(model, alpha, dofs, ranks, contact_faces_ref,
                            network=ASSUMED_NETWORK):
    """Time [s] and memory per rank [MB] at @p dofs on @p ranks (one per
    core) of the distributed mesh as it is (rank 0 reads, partitions and
    describes the whole mesh; the replicated vectors on every rank) and
    of the stage after it (the mesh read in parts, every term divided).

    Each cost per DoF is the one measured at model["dofs"]; the CG
    iterations, the two-rank run's (I2), grow as n^alpha, the contact
    faces as n^(2/3).
    """
    scale, cg, faces, solve, gather = _solve_at(
        model, alpha, dofs, ranks, contact_faces_ref, network, "I2")
    divided_work = (model["H1"] + model["D1"] * model["beta_D"]) * scale / \
        ranks
    serial = (model["G1"] + model["P2"] + model["Q2"] + model["W1"]) * scale
    surface = faces * FACE_BYTES / 2**20
    base = model["M0"]
    now = {
        "run": serial + divided_work + solve + gather,
        "memory": base + surface +
        max(model["M_mesh"] - base,
            model["M_replicated"] - base + model["M_divided"] / ranks) *
        scale,
        "serial": serial,
    }
    parts = {
        # Each rank reads, partitions (in parallel) and writes its own.
        "run": (model["G1"] + model["P2"] + model["W1"]) * scale / ranks +
        divided_work + solve + gather,
        "memory": base + surface +
        (model["M_replicated"] + model["M_divided"] - base) * scale / ranks,
    }
    return {"now": now, "parts": parts, "cg": cg}
