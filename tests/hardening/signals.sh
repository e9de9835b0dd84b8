#!/usr/bin/env bash
# All-or-nothing results under signals and concurrent runs. Runs SCENE once
# to make a complete result set, then interrupts runs on the same folder
# during the solve, during output and during the pictures (SIGINT, SIGTERM,
# SIGHUP), and requires each time: exit code 128 + signal, one line on
# stderr, the previous result set unchanged byte for byte, no staging folder
# or lock file left and no gmsh temporary folder left. Then two runs at once:
# the second is refused while the first holds the folder, and the first
# completes. With LOAD_PATH_SCENE (a scene with friction), a load path of
# 1001 cases, each staged in a folder of its own, is interrupted after its
# third case: nothing may be left beside the result folder.
# Usage: signals.sh PROGRAM SCENE [LOAD_PATH_SCENE] (SCENE: with pictures,
# its solve prints "active set iteration" lines). With LAUNCH set (e.g.
# "mpirun --oversubscribe -np 2") every run goes through it and the signal
# goes to the launcher, which passes it to every rank: the same checks (one
# line said once, nothing left) in the solve and the output, but mpirun's
# exit code is its own (1), and neither the drawing phase (shorter than
# mpirun's delay in passing a signal on: see below) nor the concurrent runs
# are repeated (SIGSTOP would stop mpirun, not the ranks).
set -u
export LC_ALL=C
launch=${LAUNCH:-}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# The command of a run (an array: the launcher's words split on purpose).
# shellcheck disable=SC2206
program=($launch "$1")
# The exit code a run stopped by signal $1 must have.
stopped_code() {
  if [ -n "$launch" ]; then echo 1; else echo $((128 + $(kill -l "$1"))); fi
}
scene=$2
load_path_scene=${3:-}
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null; [ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
cd "$work"
# The folder name holds a space, an apostrophe, a $ and a ';': data only.
folder="out put's \$x;y"
sed -e "s|^  set Folder .*||" -e "s|= \(\.\./\)*prm/|= $(cd "$(dirname "$0")/../../prm" && pwd)/|" \
  -e 's/^  set Write files .*//' -e 's/^  set Terminal .*//' "$scene" >scene.prm
printf 'subsection Output\n  set Folder = %s\n  set Pictures = true\nend\n' \
  "$folder" >>scene.prm
# Through a launcher: the distributed iterative path on a mesh refined twice
# (50 598 dofs: a solve of about 2 s; mpirun forwards the output lines late,
# and knee_small's condensed loop of 0.1 s was over before its first line
# arrived).
if [ -n "$launch" ]; then
  printf 'subsection Mesh\n  set Global refinements = 2\nend\n' >>scene.prm
  printf 'subsection Contact\n  set Solver = iterative\nend\n' >>scene.prm
fi
# Give gmsh a fresh TMPDIR so a leftover temporary folder can be seen.
export TMPDIR=$work/tmp
mkdir -p "$TMPDIR"
fail() { echo "FAIL: $*"; exit 1; }

"${program[@]}" scene.prm >first.log 2>&1 || fail "the first run exited non-zero"
[ -f "$folder/summary.json" ] && [ -f "$folder/deformation.png" ] ||
  fail "the first run wrote no complete result set"
(cd "$folder" && md5sum -- * | sort) >before.md5

wait_for() { # wait_for SECONDS COMMAND...: poll until COMMAND succeeds
  local limit=$1
  shift
  for _ in $(seq 1 $((limit * 100))); do
    "$@" && return 0
    sleep 0.01
  done
  return 1
}
in_solve() { grep -q "active set iteration" run.log; }
staged() { compgen -G ".out put's \$x;y.new-*/$1" >/dev/null; }
writing_output() { staged solution.vtu; }
# The picture process writes each figure under a temporary name, then
# renames it: a staged picture of either name means it is drawing.
drawing() { staged "*.png"; }

n=0
# Through a launcher the drawing phase is left out: knee_small draws its
# pictures in less than the 1-2 s mpirun takes to pass a signal on, so the
# signal lands after the commit (the writing_output phase's late case) and
# nothing is learnt that the phases before do not show; and once, in CI,
# it raced the job's end and stderr had more than the one line (what it
# printed was not kept: it is printed now on such a failure).
phases="in_solve writing_output drawing"
[ -z "$launch" ] || phases="in_solve writing_output"
for phase in $phases; do
  for signal in INT TERM HUP; do
    "${program[@]}" scene.prm >run.log 2>run.err &
    pid=$!
    wait_for 60 $phase || fail "$phase: never reached"
    kill -$signal $pid
    wait $pid
    code=$?
    expected=$(stopped_code $signal)
    [ $code -eq $expected ] || fail "$phase, SIG$signal: exit code $code, expected $expected"
    [ "$(wc -l <run.err)" -eq 1 ] ||
      fail "$phase, SIG$signal: stderr is not one line: $(head -c 1500 run.err)"
    outcome="result set unchanged"
    if [ -n "$launch" ] && grep -q "after its results were written" run.err; then
      # mpirun passes a signal on about 1 s late (measured: the ranks end
      # 11 ms after a signal of their own, 1-2 s after one to mpirun): the
      # run may have replaced the result set by then, whole, and says so.
      (cd "$folder" && ls | sort) | cmp -s - <(cut -c35- before.md5 | sort) ||
        fail "$phase, SIG$signal: the new result set is not whole"
      outcome="late: the new result set whole, said so"
      # The next run must leave this set as it is.
      (cd "$folder" && md5sum -- * | sort) >before.md5
    else
      (cd "$folder" && md5sum -- * | sort) | cmp -s - before.md5 ||
        fail "$phase, SIG$signal: the previous result set changed (stderr: $(cat run.err))"
    fi
    [ -z "$(ls -A "$TMPDIR")" ] || fail "$phase, SIG$signal: temporary files left in TMPDIR"
    [ "$(ls -A | grep -c "^\.out")" -eq 0 ] ||
      fail "$phase, SIG$signal: staging folder or lock left: $(ls -A)"
    n=$((n + 1))
    echo "PASS: SIG$signal $phase: exit $code, $outcome, nothing left"
  done
done

# (Through a launcher the runs above took the iterative path.)
if [ -z "$launch" ]; then
  # The iterative path initialises MPI, whose singleton keeps a session
  # folder under TMPDIR: interrupted once MPI is up (in the solve or just
  # after it), it must leave nothing there either.
  cp scene.prm iterative.prm
  printf 'subsection Contact\n  set Solver = iterative\nend\n' >>iterative.prm
  "${program[@]}" iterative.prm >run.log 2>run.err &
  pid=$!
  wait_for 60 in_solve || fail "iterative: the solve never started"
  kill -TERM $pid
  wait $pid
  code=$?
  [ $code -eq "$(stopped_code TERM)" ] ||
    fail "iterative, SIGTERM: exit code $code, expected $(stopped_code TERM)"
  grep -q "iterative" run.log || fail "iterative: the run did not take the iterative path"
  [ -z "$(ls -A "$TMPDIR")" ] ||
    fail "iterative, SIGTERM: left in TMPDIR: $(ls -AR "$TMPDIR" | head -c 300)"
  (cd "$folder" && md5sum -- * | sort) | cmp -s - before.md5 ||
    fail "iterative, SIGTERM: the previous result set changed"
  echo "PASS: SIGTERM on the iterative path (MPI up): nothing left in TMPDIR"
fi

# A load path: a folder per case inside the staging folder (the handler
# removes the whole tree, not one level).
if [ -n "$load_path_scene" ]; then
  path_folder="load path"
  sed -e 's/^  set Write files .*//' -e 's/^  set Terminal .*//' \
    -e 's/^  set Folder .*//' "$load_path_scene" >path.prm
  printf 'subsection Load cases\n  set Values of t = 0:0.001:1\nend\n' >>path.prm
  printf 'subsection Output\n  set Folder = %s\nend\n' "$path_folder" >>path.prm
  third_case() { compgen -G ".$path_folder.new-*/case_002/*" >/dev/null; }
  for signal in INT TERM; do
    "${program[@]}" path.prm >run.log 2>run.err &
    pid=$!
    wait_for 120 third_case || fail "load path: the third case never staged"
    kill -$signal $pid
    wait $pid
    code=$?
    expected=$(stopped_code $signal)
    [ $code -eq $expected ] || fail "load path, SIG$signal: exit code $code, expected $expected"
    [ "$(ls -A | grep -c "^\.load path")" -eq 0 ] ||
      fail "load path, SIG$signal: staging folder or lock left: $(ls -A)"
    [ ! -e "$path_folder" ] || fail "load path, SIG$signal: a result folder appeared"
    echo "PASS: SIG$signal during a load path (cases staged in folders): nothing left"
  done
fi

if [ -n "$launch" ]; then
  echo "PASS: $n interruptions through $launch"
  exit 0
fi

# Two runs on one folder: the second is refused with one line while the
# first lives, and the first still completes. The first is stopped
# (SIGSTOP) while the second runs, so that it cannot finish first on a
# loaded machine (it holds the folder from its start; CI once saw the
# second run start after the first had ended).
"${program[@]}" scene.prm >run.log 2>run.err &
pid=$!
wait_for 60 in_solve || fail "concurrent: the first run never reached the solve"
kill -STOP $pid
"${program[@]}" scene.prm >second.log 2>second.err
code=$?
kill -CONT $pid
[ $code -eq 1 ] || fail "concurrent: the second run exited $code, expected 1"
grep -q "another knee_contact run is writing" second.err ||
  fail "concurrent: unexpected message: $(cat second.err)"
wait $pid || fail "concurrent: the first run failed"
[ -f "$folder/summary.json" ] && [ -f "$folder/deformation.png" ] ||
  fail "concurrent: no complete result set after the first run"
echo "PASS: a second run on the same folder is refused; the first completes"
echo "PASS: $n interruptions"

# Standard output to a reader that leaves after the first line
# (`knee_contact scene.prm | head -n 1`): the run's next line raises
# SIGPIPE, which must leave nothing behind and the output folder as it was.
(cd "$folder" && md5sum -- * | sort) >before_pipe.md5
( "${program[@]}" scene.prm 2>pipe.err; echo $? >pipe.code ) | head -n 1 >/dev/null
code=$(cat pipe.code)
[ "$code" -eq 141 ] || fail "SIGPIPE: exit $code, expected 141"
grep -q "interrupted by a signal; the output folder is unchanged" pipe.err ||
  fail "SIGPIPE: unexpected message: $(cat pipe.err)"
[ "$(ls -A | grep -c "^\.out")" -eq 0 ] ||
  fail "SIGPIPE: staging folder or lock left: $(ls -A)"
(cd "$folder" && md5sum -- * | sort) | cmp -s - before_pipe.md5 ||
  fail "SIGPIPE: the output folder changed"
echo "PASS: SIGPIPE (a reader that left): nothing left, output folder unchanged"

# A rerun after an interface was renamed: the new result set replaces the
# old one whole, so the old interface's CSV is gone.
old_csv=$(cd "$folder" && ls contact_*.csv | head -n 1)
[ -n "$old_csv" ] || fail "rename: no contact CSV in the first result set"
sed -e 's/^\( *set Name *= *\)condyle$/\1renamed_condyle/' -e 's/condyle:/renamed_condyle:/' scene.prm >renamed.prm
grep -q renamed_condyle renamed.prm || fail "rename: no interface named condyle"
"${program[@]}" renamed.prm >rename.log 2>&1 || fail "rename: the rerun failed: $(tail -n 1 rename.log)"
[ -f "$folder/contact_renamed_condyle.csv" ] || fail "rename: new CSV missing"
[ ! -e "$folder/contact_condyle.csv" ] || fail "rename: stale contact_condyle.csv left"
echo "PASS: a renamed interface leaves no stale CSV"
