#!/usr/bin/env python3
"""Fuzz test: hostile variants of the example scenes and meshes.

Every numeric value of the given scenes is a candidate for a mutation (nan,
inf, -1, 0, 1e308, -1e308, text); a fixed-seed sample of them is run, plus
every scene and mesh truncated at several offsets. Each run must end within
a time limit with exit code 0, 1, 2 or 3 (a mutated value may still be a
valid scene), never a crash (signal, abort), an internal error (exit 4), a
sanitizer report or a hang; exit code 1 must come with exactly one line on
stderr, "knee_contact: error: ...".

Usage: fuzz.py PROGRAM N_MUTANTS SCENE... (meshes: the .geo/.msh the scenes
use are truncated too)
"""
import concurrent.futures
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile

MUTATIONS = ["nan", "inf", "-inf", "-1", "0", "1e308", "-1e308", "1e-320",
             "abc", "", "1e999", "0x1p3", "2147483648", "-2147483649"]
NUMBER = re.compile(r"(?<![\w.])[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(?![\w.])")
TIME_LIMIT = 120


def prepare(scene_text, scene_dir, work):
    """Absolute mesh paths, files into the work folder, no pictures."""
    lines = []
    for line in scene_text.splitlines():
        stripped = line.strip()
        if re.match(r"set\s+(Folder|Pictures|Write files|Terminal)\s*=",
                    stripped):
            continue
        m = re.match(r"(\s*set\s+File\s*=\s*)(\S.*)$", line)
        if m and not os.path.isabs(m.group(2).strip()):
            line = m.group(1) + os.path.normpath(
                os.path.join(scene_dir, m.group(2).strip()))
        lines.append(line)
    lines += ["subsection Output", "  set Folder = " + work + "/out",
              "  set Pictures = false", "  set Terminal = test", "end"]
    return "\n".join(lines) + "\n"


def run(program, name, text, work):
    path = os.path.join(work, "scene.prm")
    with open(path, "w", encoding="utf-8", errors="surrogateescape") as f:
        f.write(text)
    env = dict(os.environ, DEAL_II_NUM_THREADS="1")
    try:
        p = subprocess.run([program, path], cwd=work, env=env,
                           capture_output=True, timeout=TIME_LIMIT)
    except subprocess.TimeoutExpired:
        return f"{name}: no exit within {TIME_LIMIT} s (hang)"
    err = p.stderr.decode("utf-8", "replace")
    if p.returncode < 0 or p.returncode >= 128:
        return f"{name}: crashed (exit {p.returncode}): {err[-300:]}"
    if p.returncode not in (0, 1, 2, 3):
        return f"{name}: exit {p.returncode}: {err[-300:]}"
    if re.search(r"runtime error|AddressSanitizer|LeakSanitizer", err):
        return f"{name}: sanitizer report: {err[-300:]}"
    if p.returncode == 1:
        lines = err.splitlines()
        if len(lines) != 1 or not lines[0].startswith("knee_contact: error:"):
            return f"{name}: exit 1 without one error line: {err[-300:]}"
    return p.returncode


def main():
    program, n_mutants, scenes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
    rng = random.Random(20261122)
    cases = []  # (name, scene text, extra files {name: bytes})
    meshes = set()
    for scene in scenes:
        text = open(scene, encoding="utf-8").read()
        scene_dir = os.path.dirname(os.path.abspath(scene))
        base = prepare(text, scene_dir, "@WORK@")
        for m in re.finditer(r"set\s+File\s*=\s*(\S.*)", text):
            meshes.add((scene, os.path.normpath(
                os.path.join(scene_dir, m.group(1).strip()))))
        # Numeric values of 'set' lines.
        spots = []
        for i, line in enumerate(base.splitlines()):
            if re.match(r"\s*set\s", line) and "@WORK@" not in line:
                value_start = line.find("=") + 1
                for n in NUMBER.finditer(line, value_start):
                    spots.append((i, n.start(), n.end()))
        for (i, a, b) in rng.sample(spots, min(len(spots), n_mutants)):
            lines = base.splitlines()
            mutation = rng.choice(MUTATIONS)
            lines[i] = lines[i][:a] + mutation + lines[i][b:]
            cases.append((f"{os.path.basename(scene)}: line '"
                          f"{lines[i].strip()[:80]}'",
                          "\n".join(lines) + "\n"))
        # Truncated scenes.
        for fraction in (0.1, 0.35, 0.6, 0.85):
            cut = base[: int(len(base) * fraction)]
            cases.append((f"{os.path.basename(scene)} truncated at "
                          f"{fraction:.2f}", cut))
    # Truncated meshes, each used by the scene that names it.
    for scene, mesh in sorted(meshes):
        if not os.path.exists(mesh):
            continue
        data = open(mesh, "rb").read()
        scene_dir = os.path.dirname(os.path.abspath(scene))
        base = prepare(open(scene, encoding="utf-8").read(), scene_dir,
                       "@WORK@")
        ext = os.path.splitext(mesh)[1]
        for fraction in (0.05, 0.3, 0.5, 0.7, 0.95):
            cases.append((f"{os.path.basename(mesh)} truncated at "
                          f"{fraction:.2f}",
                          base.replace(mesh, "@WORK@/mesh" + ext),
                          ("mesh" + ext, data[: int(len(data) * fraction)])))

    return run_cases(program, cases, "hostile variants")


def run_cases(program, cases, what):
    """Run the cases (name, scene text with @WORK@ for the work folder[,
    (file name, bytes or (bytes, size of a sparse file)) written into
    it]) two at a time; print the exit
    codes and the failures; 1 if any case failed, else 0."""
    def one(case):
        name, text = case[0], case[1]
        work = tempfile.mkdtemp(prefix="knee_fuzz_")
        try:
            if len(case) > 2:
                content = case[2][1]
                with open(os.path.join(work, case[2][0]), "wb") as f:
                    # (bytes, size): a sparse file of size.
                    if isinstance(content, tuple):
                        f.write(content[0])
                        f.truncate(content[1])
                    else:
                        f.write(content)
            return run(program, name, text.replace("@WORK@", work), work)
        finally:
            shutil.rmtree(work, ignore_errors=True)

    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        outcomes = list(pool.map(one, cases))
    failures = [f for f in outcomes if isinstance(f, str)]
    for code in (0, 1, 2, 3):
        print(f"exit code {code}: {outcomes.count(code)} variants")
    for f in failures:
        print("FAIL:", f)
    print(f"{len(cases) - len(failures)} of {len(cases)} {what} "
          "handled (exit 0-3, one error line for exit 1, no crash or hang)")
    return 1 if failures else 0

if __name__ == "__main__":
    sys.exit(main())
