#!/usr/bin/env bash
# Runs SCENE three times, twice with 2 threads and once with 1
# (DEAL_II_NUM_THREADS), writing files, and passes only if every number of
# summary.json except the wall times is identical bit for bit (as printed,
# 17 significant digits) across the three runs.
# Usage: deterministic.sh PROGRAM SCENE
set -u
export LC_ALL=C
# OpenBLAS as a user runs it (ctest sets one thread for every test).
unset OPENBLAS_NUM_THREADS
program=$1
scene=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for run in a b c; do
  sed -e 's/^  set Write files = false/  set Write files = true\n  set Pictures    = false\n  set Folder      = '"$run"'/' \
      -e "s|= \(\.\./\)*prm/|= $(cd "$(dirname "$0")/../../prm" && pwd)/|" "$scene" >"$work/$run.prm"
  threads=2
  [ $run = c ] && threads=1
  (cd "$work" && DEAL_II_NUM_THREADS=$threads "$program" "$run.prm" >/dev/null) ||
    { echo "FAIL: run $run exited non-zero"; exit 1; }
  /usr/bin/python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
d.pop("wall_time", None)
d["solver"] = {k: v for k, v in d.get("solver", {}).items()
               if k in ("name", "contact_unknowns")}
print(json.dumps(d, sort_keys=True))' "$work/$run/summary.json" >"$work/$run.json" ||
    { echo "FAIL: run $run wrote no readable summary.json"; exit 1; }
  # A summary without its results would compare equal too.
  grep -q '"energy"' "$work/$run.json" ||
    { echo "FAIL: run $run: summary.json holds no energy"; exit 1; }
done
if cmp -s "$work/a.json" "$work/b.json" && cmp -s "$work/a.json" "$work/c.json"; then
  echo "PASS: summary.json identical across 2 runs with 2 threads and 1 run with 1 thread"
else
  /usr/bin/python3 -c '
import json, sys
runs = [json.loads(open(f).read()) for f in sys.argv[1:]]
def walk(a, others, path):
    if isinstance(a, dict):
        for k in a:
            walk(a[k], [o[k] for o in others], path + "/" + k)
    elif any(o != a for o in others):
        print("differs:", path, a, others)
walk(runs[0], runs[1:], "")' "$work/a.json" "$work/b.json" "$work/c.json"
  echo "FAIL: results differ between runs"
  exit 1
fi
