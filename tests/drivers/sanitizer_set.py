#!/usr/bin/env python3
"""Which tests CI's sanitizer stage needs: per-test line coverage.

Runs every test labelled "sanitizer" (and those an earlier choice took out
of it) alone in a build made with gcov instrumentation
(tests/drivers/sanitizer_coverage.sh makes one), each with its own
GCOV_PREFIX, so that each test's executed lines of source/ are known, each
template instantiation of a line apart (2D and 3D). Then chooses, greedily
by new lines per second of the sanitizer build's run time (ctest's record
in the sanitizer build, or the coverage build's own), a set that executes
every line the whole label executes, and
prints the tests left out: each of them executes no line of source/ that
the chosen set does not. With --write, writes their names to
tests/sanitizer_redundant.txt, which tests/CMakeLists.txt reads: those
tests leave the "sanitizer" label (the release stage runs them all).

gcov writes no counts for a run ended by a signal or std::_Exit, so a test
whose point is such a run (signals, out of memory) may look redundant when
it is not: KEEP below names the tests kept whatever their lines, with the
reason.

Usage: sanitizer_set.py [--write] COVERAGE_BUILD [SANITIZER_COST_FILE]
  (COVERAGE_BUILD already built with --coverage; the cost file is
  build-asan/Testing/Temporary/CTestCostData.txt of a sanitizer run)
"""

import collections
import concurrent.futures
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys

# Kept in the sanitizer set whatever their lines: hostile input and
# interrupted runs are what the sanitizers are there for, and their signal
# and _Exit endings leave no gcov counts.
KEEP = {
    "hardening/fuzz": "hostile values: the sanitizers' first target",
    "hardening/reader_fuzz": "damaged mesh files: the sanitizers' first "
                             "target",
    "hardening/hostile_files": "huge and deeply nested files",
    "hardening/signals_and_concurrent_runs": "runs ended by signals leave "
                                             "no gcov counts",
    "hardening/out_of_memory": "ends by std::_Exit: no gcov counts",
}


def tests_of(build, label):
    listing = subprocess.run(
        ["ctest", "--test-dir", build, "-N"] + (["-L", label] if label else []),
        capture_output=True, text=True, check=True).stdout
    return re.findall(r"Test\s+#\d+: (\S+)", listing)


def run_one(build, root, name):
    """Runs one test with its own GCOV_PREFIX (once: a finished run's
    counts are kept, so that the choice can be redone cheaply)."""
    prefix = root / name.replace("/", "+")
    done = prefix / "exit_code"
    if done.exists():
        return name, int(done.read_text())
    shutil.rmtree(prefix, ignore_errors=True)
    prefix.mkdir(parents=True)
    # deal.II's test machinery skips a run whose output is newer than the
    # program: remove it, so that the program runs here.
    for stamp in ("output", "diff"):
        path = pathlib.Path(build, "tests", name, stamp)
        if path.exists():
            path.unlink()
    env = dict(os.environ, GCOV_PREFIX=str(prefix), GCOV_PREFIX_STRIP="0")
    result = subprocess.run(
        ["ctest", "--test-dir", build, "-R", "^" + re.escape(name) + "$",
         "--output-on-failure"],
        capture_output=True, text=True, env=env)
    done.write_text(str(result.returncode))
    return name, result.returncode


def lines_of(source, prefix):
    """The (file, line, function) triples of source/ that the counts under
    prefix executed: a template's line counts once per instantiation (a
    line run in 2D only is not run in 3D)."""
    executed = set()
    for gcda in prefix.rglob("*.gcda"):
        original = pathlib.Path("/") / gcda.relative_to(prefix)
        gcno = original.with_suffix(".gcno")
        if not gcno.exists():
            continue
        link = gcda.with_suffix(".gcno")
        if not link.exists():
            link.symlink_to(gcno)
        out = subprocess.run(
            ["gcov", "--json-format", "--stdout", "-o", str(gcda.parent),
             gcda.name],
            capture_output=True, cwd=str(original.parent))
        for text in out.stdout.decode(errors="replace").splitlines():
            if not text.startswith("{"):
                continue
            data = json.loads(text)
            for entry in data.get("files", []):
                path = os.path.normpath(
                    os.path.join(data.get("current_working_directory", ""),
                                 entry["file"]))
                if not path.startswith(source):
                    continue
                relative = path[len(source):]
                for line in entry["lines"]:
                    if line["count"] > 0:
                        executed.add((relative, line["line_number"],
                                      line.get("function_name", "")))
    return executed


def costs(path):
    times = {}
    if path and os.path.exists(path):
        for text in open(path):
            parts = text.split()
            if len(parts) == 3:
                times[parts[0]] = float(parts[2])
    return times


def main():
    arguments = sys.argv[1:]
    write = "--write" in arguments
    arguments = [a for a in arguments if a != "--write"]
    build = os.path.abspath(arguments[0])
    cost_file = arguments[1] if len(arguments) > 1 else os.path.join(
        build, "Testing", "Temporary", "CTestCostData.txt")
    project = pathlib.Path(__file__).resolve().parents[2]
    source = str(project / "source") + "/"
    root = pathlib.Path(build) / "per_test_coverage"
    # The candidates: the label as it is and the tests an earlier choice
    # took out of it.
    listed = project / "tests" / "sanitizer_redundant.txt"
    every = tests_of(build, "")
    names = tests_of(build, "sanitizer")
    if listed.exists():
        names += [name for name in listed.read_text().splitlines()
                  if name in every and name not in names]
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        runs = list(pool.map(lambda name: run_one(build, root, name),
                             names))
    failed = [name for name, code in runs if code != 0]
    if failed:
        print("failed in the coverage build:", " ".join(failed))
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        covered = dict(zip(names, pool.map(
            lambda name: lines_of(source, root / name.replace("/", "+")),
            names)))
    union = set().union(*covered.values())
    times = costs(cost_file)
    chosen = [name for name in names if name in KEEP]
    have = set().union(*(covered[name] for name in chosen)) if chosen \
        else set()
    left = [name for name in names if name not in KEEP]
    while True:
        best, best_rate = None, 0.
        for name in left:
            new = len(covered[name] - have)
            if new == 0:
                continue
            rate = new / max(times.get(name, 1.), 0.1)
            if rate > best_rate:
                best, best_rate = name, rate
        if best is None:
            break
        chosen.append(best)
        have |= covered[best]
        left.remove(best)
    assert have == union
    per_file = collections.Counter(unit[0] for unit in union)
    lines = len({unit[:2] for unit in union})
    print(f"{len(names)} tests, {lines} lines of source/ executed in "
          f"{len(per_file)} files ({len(union)} counting each template "
          "instantiation of a line)")
    total = sum(times.get(name, 0.) for name in names)
    kept = sum(times.get(name, 0.) for name in chosen)
    print(f"chosen: {len(chosen)} tests, {kept:.0f} s of {total:.0f} s "
          "(sum of the tests' times in the cost file)")
    for name in chosen:
        unique = covered[name] - set().union(
            *(covered[other] for other in chosen if other != name))
        print(f"  keep {name:55s} {times.get(name, 0.):7.1f} s "
              f"{len(covered[name]):6d} lines, {len(unique):5d} only here"
              + (f"  (kept: {KEEP[name]})" if name in KEEP else ""))
    print("redundant (every line also executed by the chosen set):")
    for name in sorted(left):
        print(f"  {name:55s} {times.get(name, 0.):7.1f} s "
              f"{len(covered[name]):6d} lines")
    if write and not failed:
        with open(project / "tests" / "sanitizer_redundant.txt", "w") as out:
            out.write(
                "# Written by tests/drivers/sanitizer_set.py --write: tests "
                "whose executed lines\n# of source/ (each template "
                "instantiation apart) the rest of the sanitizer\n# label "
                "executes too; they leave that label (CI's sanitizer "
                f"stage).\n# {len(union)} lines and instantiations in "
                f"{len(per_file)} files; the label keeps {len(chosen)} of "
                f"{len(names)} tests,\n# {kept:.0f} s of {total:.0f} s "
                "in the sanitizer build.\n")
            out.writelines(name + "\n" for name in sorted(left))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
