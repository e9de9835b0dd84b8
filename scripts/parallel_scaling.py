#!/usr/bin/python3
"""The same scene on 1, 2, 4, ... ranks: a table of times and memory.

Usage: parallel_scaling.py KNEE_CONTACT SCENE.prm [--ranks 1 2 4]
           [--repeat 3] [--solver iterative]
           [--model [--small SMALLER_SCENE.prm]]

N = 1 runs as one process (no mpirun); N > 1 under mpirun (oversubscribed
where N exceeds the cores: the communication terms show, the speed-up
cannot). Each run writes its results into a folder of its own
(output/scaling/<scene>_<N>_<k>) and the table is read from its
summary.json: the whole run, the contact solve, the Krylov and AMG set-up
times of the iterative path, CG iterations, the peak resident memory of
rank 0 and the largest relative difference of the contact forces and
peak pressures from the one-process run. Times are the median over
--repeat runs; the ratios are of medians measured in this one invocation
(the machine is noisy).

A second table gives the largest rank's memory against issue 38's bound,
1.2 x (the first N's peak / N + the contact rows every rank holds): its
resident peak as the kernel keeps it (VmHWM, summary.json) and, sampled
every 0.5 s from /proc, its resident set (Rss) and proportional share
(Pss: a page that k ranks map, the libraries' code say, counted 1/k in
each).

With --repeat R > 1 the runs go in R rounds, each round one run of every
N (1, 2, 4, 1, 2, 4, ...), so that a slow hour of the machine slows every
N alike, and before and after every run a probe times a fixed
memory-bound kernel on both cores at once (two processes, each a triad
over 3 x 160 MB): a table of the rounds gives each run beside the slower
of its two probes, the ratios of the
first N's run to the others' in the round, and their median over the
rounds, over every round and over the rounds whose probes were all
within 10 % of the fastest probe (the machine at its own speed).

--model (ranks 1 and 2 needed) fits scaling_model.py's constants to the
N = 1 and N = 2 runs, prints its prediction beside each measured N (N = 4
on this 2-core machine checks its oversubscription and communication
terms), and extrapolates to 1e7 and 1e8 DoFs on 16-256 ranks. --small
names the same model at a smaller size, run on one rank for the CG
iterations' growth with the DoFs (else they are taken constant).
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scaling_model  # noqa: E402


class MemorySampler:
    """Every 0.5 s, the resident set (Rss) and proportional share (Pss) of
    each process of @p binary started under the process @p pid (mpirun's
    ranks, or the one process), from /proc/<pid>/smaps_rollup: the peaks
    of each (peaks()). Pss counts a page that k processes map 1/k to
    each (the libraries' code, mapped by every rank: one copy in the
    machine's memory); Rss counts it whole in every rank. The kernel keeps
    no peak of Pss (VmHWM is Rss's), hence the sampling."""

    def __init__(self, pid, binary):
        self.pid, self.binary = pid, os.path.realpath(binary)
        self.rss, self.pss = {}, {}
        self.done = threading.Event()
        self.thread = threading.Thread(target=self.sample, daemon=True)
        self.thread.start()

    def processes(self):
        """The processes of the binary in the tree under self.pid."""
        children = {}
        for entry in os.listdir("/proc"):
            if not entry.isdigit():
                continue
            try:
                with open("/proc/%s/stat" % entry) as f:
                    parent = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, ValueError, IndexError):
                continue
            children.setdefault(parent, []).append(int(entry))
        tree, found = [self.pid], []
        while tree:
            pid = tree.pop()
            tree.extend(children.get(pid, []))
            try:
                if os.path.realpath("/proc/%d/exe" % pid) == self.binary:
                    found.append(pid)
            except OSError:
                pass
        return found

    def sample(self):
        while not self.done.wait(0.5):
            for pid in self.processes():
                try:
                    with open("/proc/%d/smaps_rollup" % pid) as f:
                        fields = dict(line.split()[:2] for line in f
                                      if line.startswith(("Rss:", "Pss:")))
                except (OSError, ValueError):
                    continue
                for key, peaks in (("Rss:", self.rss), ("Pss:", self.pss)):
                    if key in fields:
                        peaks[pid] = max(peaks.get(pid, 0),
                                         int(fields[key]) / 1024.)

    def peaks(self):
        """The largest process's sampled Rss and Pss peaks [MB]."""
        self.done.set()
        self.thread.join()
        return (max(self.rss.values(), default=0.),
                max(self.pss.values(), default=0.))


def run(binary, scene_text, folder, ranks):
    """One run; its summary.json (with the sampled peaks added as
    "sampled_rss_MB" and "sampled_pss_MB") and wall time."""
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
    process = subprocess.Popen(command, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=env)
    sampler = MemorySampler(process.pid, binary)
    _, errors = process.communicate()
    seconds = time.monotonic() - start
    rss, pss = sampler.peaks()
    if process.returncode != 0:
        sys.exit("%s on %d ranks failed (%d): %s" %
                 (scene, ranks, process.returncode, errors[-2000:]))
    with open(os.path.join(folder, "summary.json")) as f:
        summary = json.load(f)
    summary["sampled_rss_MB"], summary["sampled_pss_MB"] = rss, pss
    return summary, seconds


PROBE = """
import numpy, time
b = numpy.ones(20000000); c = numpy.ones(20000000); a = numpy.empty_like(b)
a[:] = b + 3.0 * c
start = time.monotonic()
for _ in range(20):
    numpy.multiply(c, 3.0, out=a)
    numpy.add(a, b, out=a)
print(time.monotonic() - start)
"""


def probe():
    """Seconds of the probe (PROBE) on both cores at once: the slower of
    two processes started together (numpy from Debian's Python)."""
    workers = [subprocess.Popen(["/usr/bin/python3", "-c", PROBE],
                                stdout=subprocess.PIPE, text=True)
               for _ in range(2)]
    return max(float(worker.communicate()[0]) for worker in workers)


def print_rounds(ranks, rounds):
    """Each round's runs and probes, the ratios of the first N's run to
    the others', and their medians (all rounds; the quiet ones)."""
    fastest = min(p for r in rounds for _, p in r.values())
    print("\n| round | " + " | ".join(
        "N = %d: run [s] (probe [s])" % n for n in ranks) + " | " +
        " | ".join("ratio %d / %d" % (ranks[0], n) for n in ranks[1:]) +
        " | quiet |")
    print("|" + "---|" * (2 * len(ranks) + 1))
    ratios, quiet = [], []
    for k, r in enumerate(rounds):
        row = [r[n][0] and r[ranks[0]][0] / r[n][0] for n in ranks[1:]]
        calm = all(p <= 1.1 * fastest for _, p in r.values())
        ratios.append(row)
        if calm:
            quiet.append(row)
        print("| %d | %s | %s | %s |" % (
            k + 1, " | ".join("%.1f (%.2f)" % r[n] for n in ranks),
            " | ".join("%.2f" % x for x in row), "yes" if calm else "no"))
    for name, chosen in (("every round", ratios), ("quiet rounds", quiet)):
        if chosen:
            print("median ratio over %s (%d): %s" % (
                name, len(chosen), ", ".join(
                    "%d / %d %.2f" % (ranks[0], n, statistics.median(
                        row[i] for row in chosen))
                    for i, n in enumerate(ranks[1:]))))


def print_memory(rows):
    """The largest rank's memory against issue 38's bound, 1.2 x (the first
    row's peak / N + the rows every rank holds whole), in the kernel's
    resident peak (VmHWM, summary.json) and in the sampled Rss and Pss
    peaks (MemorySampler)."""
    base = rows[0]
    print("\n| ranks | largest rank's peak (VmHWM) [MB] | sampled Rss peak "
          "[MB] | sampled Pss peak [MB] | replicated rows [MB] | bound 1.2 x "
          "(%d's / N + replicated) [MB] | VmHWM / bound | Pss / bound |"
          % base["ranks"])
    print("|" + "---|" * 8)
    for row in rows:
        bound = 1.2 * (base["largest_peak"] * base["ranks"] / row["ranks"] +
                       row["replicated"])
        print("| %d | %.0f | %.0f | %.0f | %.1f | %.0f | %.3f | %.3f |" % (
            row["ranks"], row["largest_peak"], row["sampled_rss"],
            row["sampled_pss"], row["replicated"], bound,
            row["largest_peak"] / bound, row["sampled_pss"] / bound))


def contact_numbers(summary):
    """Forces and peak pressures of every interface."""
    values = {}
    for name, interface in summary.get("contact_interfaces", {}).items():
        for key in ("force", "max_pressure"):
            values[name + "/" + key] = interface[key]
    return values


def rank_zero_alone(summary, seconds):
    """The time of a run's work on rank 0 alone: the output, and what its
    timers do not see (gmsh and the mesh checks, before the first cycle:
    rank 0 alone meshes under mpirun; starting the program)."""
    timed = sum(v for k, v in summary["wall_time"].items() if ": " not in k)
    times = summary["wall_time"]
    return times.get("output", 0) + times.get("pictures", 0) + \
        max(seconds - timed, 0.)


def scene_text(scene, solver):
    """The scene's text for a run: its files found from anywhere, @p solver
    (if given) as Contact/Solver, the output into @FOLDER@, no pictures."""
    scene = os.path.abspath(scene)
    text = open(scene).read()
    # Relative paths of the scene (meshes) from its folder.
    here = os.path.dirname(scene)
    text = re.sub(r"(set File\s*=\s*)(\S+)",
                  lambda m: m.group(1) + os.path.normpath(
                      os.path.join(here, m.group(2))), text)
    if solver:
        text = re.sub(r"\n\s*set Solver\s*=.*", "", text)
        text = text.replace("subsection Contact", "subsection Contact\n"
                            "  set Solver = %s" % solver, 1)
    text = re.sub(r"\n\s*set (Folder|Terminal|Write files|Pictures)\s*=.*",
                  "", text)
    if "subsection Output" not in text:
        text += "subsection Output\nend\n"
    return text.replace("subsection Output", "subsection Output\n"
                        "  set Folder = @FOLDER@\n  set Pictures = false", 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary")
    parser.add_argument("scene")
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4])
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--solver", default=None,
                        help="Contact/Solver for every run (default: the "
                        "scene's)")
    parser.add_argument("--model", action="store_true",
                        help="fit and check the scaling model")
    parser.add_argument("--small", default=None,
                        help="the scene at a smaller size (--model)")
    args = parser.parse_args()
    binary = os.path.abspath(args.binary)
    scene = os.path.abspath(args.scene)
    text = scene_text(scene, args.solver)
    stem = os.path.splitext(os.path.basename(scene))[0]

    # Rounds of one run of every N (see the docstring).
    by_ranks = {ranks: [] for ranks in args.ranks}
    rounds = []
    before = probe() if args.repeat > 1 else 0.
    for k in range(args.repeat):
        rounds.append({})
        for ranks in args.ranks:
            by_ranks[ranks].append(run(binary, text, os.path.abspath(
                os.path.join("output", "scaling", "%s_%d_%d" % (
                    stem, ranks, k))), ranks))
            after = probe() if args.repeat > 1 else 0.
            rounds[-1][ranks] = (by_ranks[ranks][-1][1], max(before, after))
            before = after

    rows, reference = [], None
    for ranks in args.ranks:
        runs = by_ranks[ranks]
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
            "path_measured": median(
                lambda s: s["solver"].get("iterative_memory_MB", 0)),
            "peak": median(lambda s: s["solver"].get("peak_memory_MB", 0)),
            "output": statistics.median(
                rank_zero_alone(summary, seconds) for summary, seconds in runs),
            "pairs": summaries[0].get("n_contact_pairs", 0),
            "distributed": summaries[0]["solver"].get("distributed_mesh", 0),
            "mesh": median(lambda s: s["wall_time"].get("mesh", 0)),
            "read": median(lambda s: s["wall_time"].get("mesh: read", 0)),
            "partition": median(
                lambda s: s["wall_time"].get("mesh: partition", 0)),
            "descriptions": median(
                lambda s: s["wall_time"].get("mesh: descriptions", 0)),
            "part": median(lambda s: s["wall_time"].get("mesh: part", 0)),
            "mesh_peak": median(
                lambda s: s["solver"].get("mesh_peak_memory_MB", 0)),
            "largest_peak": median(lambda s: s["solver"].get(
                "largest_rank_peak_memory_MB",
                s["solver"].get("peak_memory_MB", 0))),
            "replicated": median(
                lambda s: s["solver"].get("replicated_rows_MB", 0)),
            "sampled_rss": median(lambda s: s["sampled_rss_MB"]),
            "sampled_pss": median(lambda s: s["sampled_pss_MB"]),
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
                  row["path_measured"], row["peak"], row["difference"]))
    print_memory(rows)
    if args.repeat > 1:
        print_rounds(args.ranks, rounds)
    if args.model:
        # The program's own memory (its libraries): a scene of a few cells.
        tiny, _ = run(binary, scene_text(os.path.join(
            os.path.dirname(os.path.abspath(__file__)), "..", "tests",
            "scenes", "contact_patch_3d_hex.prm"), None),
            os.path.abspath(os.path.join("output", "scaling", "base")), 1)
        small = None
        if args.small:
            folder = os.path.abspath(
                os.path.join("output", "scaling", stem + "_small"))
            summary, _ = run(binary, scene_text(args.small, args.solver),
                             folder, 1)
            small = {"dofs": summary["n_dofs"],
                     "cg": summary["solver"].get("krylov_iterations", 0)}
        print_model(rows, small, tiny["solver"].get("peak_memory_MB", 0))


def print_model(rows, small, base):
    """The model fitted to N = 1, 2 beside every measured N, and its
    extrapolation (scaling_model.py)."""
    by_ranks = {row["ranks"]: row for row in rows}
    if 1 not in by_ranks or 2 not in by_ranks:
        sys.exit("--model needs runs on 1 and 2 ranks")
    if by_ranks[2]["distributed"]:
        print_distributed_model(by_ranks, small, base)
        return
    model = scaling_model.fit(by_ranks[1], by_ranks[2])
    cores = os.cpu_count()
    print("\nModel (scripts/scaling_model.py) fitted to N = 1, 2 on %d cores:"
          % cores)
    print(", ".join("%s %.4g" % (k, v) for k, v in model.items()))
    print("\n| ranks | run measured [s] | model [s] | model with measured "
          "CG it. [s] | error | R meas. / model [s] | K meas. / model [s] "
          "| memory per rank meas. / model [MB] |")
    print("|" + "---|" * 8)
    for row in rows:
        assumed = scaling_model.predict(model, row["ranks"], cores)
        with_cg = scaling_model.predict(model, row["ranks"], cores,
                                        iterations=row["cg"])
        print("| %d | %.1f | %.1f | %.1f | %+.0f %% | %.1f / %.1f "
              "| %.1f / %.1f | %.0f / %.0f |" % (
                  row["ranks"], row["run"], assumed["run"], with_cg["run"],
                  100 * (assumed["run"] / row["run"] - 1),
                  scaling_model.replicated(row), assumed["R"], row["krylov"],
                  assumed["K"], row["peak"], assumed["memory"]))
    alpha = print_extrapolation_basis(small, by_ranks[1])
    print("\n| DoFs | ranks | CG it. | this stage: run [s] / memory per "
          "rank [GB] | distributed stage: run [s] / memory per rank [GB] |")
    print("|---|---|---|---|---|")
    for dofs in (1e7, 1e8):
        for ranks in (16, 64, 256):
            e = scaling_model.extrapolate(model, alpha, dofs, ranks,
                                          2 * by_ranks[1]["pairs"])
            print("| %.0e | %d | %.0f | %.0f / %.1f | %.0f / %.2f |" % (
                dofs, ranks, e["cg"], e["stage"]["run"],
                e["stage"]["memory"] / 1024, e["distributed"]["run"],
                e["distributed"]["memory"] / 1024))


def print_extrapolation_basis(small, one):
    """The CG iterations' growth exponent from the --small run and the
    one-rank run @p one (0 without --small), printed with the network the
    extrapolations assume; returns the exponent."""
    alpha = 0.0
    if small:
        alpha = scaling_model.iteration_exponent(small, one)
        print("\nCG iterations %d at %d DoFs, %d at %d: alpha %.2f" % (
            small["cg"], small["dofs"], one["cg"], one["dofs"], alpha))
    print("\nExtrapolated (network assumed: %s; one rank per core):" %
          scaling_model.ASSUMED_NETWORK)
    return alpha


def print_distributed_model(by_ranks, small, base):
    """print_model() for runs on the distributed mesh; @p base the peak
    memory of a scene of a few cells [MB]."""
    model = scaling_model.fit_distributed(by_ranks[1], by_ranks[2], base)
    cores = os.cpu_count()
    print("\nModel of the distributed mesh (scripts/scaling_model.py) fitted "
          "to N = 1, 2 on %d cores:" % cores)
    print(", ".join("%s %.4g" % (k, v) for k, v in model.items()))
    print("\n| ranks | run measured [s] | model [s] | model with measured "
          "CG it. [s] | error | mesh meas. / model [s] | of which rank 0's "
          "descriptions meas. / model [s] | D meas. / model [s] "
          "| K meas. / model [s] | rank 0's memory meas. / model [MB] |")
    print("|" + "---|" * 10)
    for ranks, row in sorted(by_ranks.items()):
        assumed = scaling_model.predict_distributed(model, ranks, cores)
        with_cg = scaling_model.predict_distributed(model, ranks, cores,
                                                    iterations=row["cg"])
        print("| %d | %.1f | %.1f | %.1f | %+.0f %% | %.1f / %.1f "
              "| %.1f / %.1f | %.1f / %.1f | %.1f / %.1f | %.0f / %.0f |" % (
                  ranks, row["run"], assumed["run"], with_cg["run"],
                  100 * (assumed["run"] / row["run"] - 1), row["mesh"],
                  assumed["mesh"], row["descriptions"], assumed["Q"],
                  scaling_model.divided(row), assumed["D"], row["krylov"],
                  assumed["K"], row["peak"], assumed["memory"]))
    alpha = print_extrapolation_basis(small, by_ranks[1])
    print("\n| DoFs | ranks | CG it. | as now: run [s] (rank 0's serial "
          "part) / rank 0's memory [GB] | the mesh read in parts: run [s] / "
          "memory per rank [GB] |")
    print("|---|---|---|---|---|")
    for dofs in (1e7, 1e8):
        for ranks in (16, 64, 256):
            e = scaling_model.extrapolate_distributed(
                model, alpha, dofs, ranks, 2 * by_ranks[1]["pairs"])
            print("| %.0e | %d | %.0f | %.0f (%.0f) / %.1f | %.0f / %.2f |" % (
                dofs, ranks, e["cg"], e["now"]["run"], e["now"]["serial"],
                e["now"]["memory"] / 1024, e["parts"]["run"],
                e["parts"]["memory"] / 1024))


if __name__ == "__main__":
    main()
