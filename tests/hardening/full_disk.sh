#!/usr/bin/env bash
# A full disk during output: the output folder lies on a small tmpfs (200 kB;
# uniaxial_block writes 16 kB, knee_small 350 kB) that
# holds SMALL's result set but not BIG's. The run of BIG must exit 1 with
# one line that says the device is full, leave SMALL's result set unchanged
# and leave no staging folder. Needs root to mount the tmpfs; skipped
# (exit 77) otherwise. With LAUNCH set (e.g. "mpirun --oversubscribe -np
# 2") BIG runs through it: rank 0 writes the folder while rank 1 builds its
# pieces of solution.vtu and sends them; when rank 0 cannot write, it still
# takes the pieces to come, so the run ends with rank 0's own line, said
# once, not with a rank left waiting that MPI_Abort ends after 30 s (whose
# line would name its rank). mpirun adds its own lines and its exit code
# (1). Usage: full_disk.sh PROGRAM SMALL BIG
set -u
export LC_ALL=C
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
launch=${LAUNCH:-}
program=$1
small=$2
big=$3
work=$(mktemp -d)
trap 'umount "$work/disk" 2>/dev/null; rm -rf "$work"' EXIT
mkdir "$work/disk"
mount -t tmpfs -o size=200k tmpfs "$work/disk" 2>/dev/null ||
  { echo "SKIP: cannot mount a tmpfs (not root)"; exit 77; }
cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
for s in small big; do
  scene=${!s}
  sed -e "s|^  set Folder .*||" -e "s|= \(\.\./\)*prm/|= $(cd "$(dirname "$0")/../../prm" && pwd)/|" \
    -e 's/^  set Write files .*//' -e 's/^  set Pictures .*//' "$scene" >$s.prm
  printf 'subsection Output\n  set Folder = disk/out\n  set Pictures = false\nend\n' >>$s.prm
done
"$program" small.prm >small.log 2>&1 || fail "the small run failed: $(tail -n 1 small.log)"
(cd disk/out && md5sum -- * | sort) >before.md5
# The launcher's words split on purpose.
# shellcheck disable=SC2086
$launch "$program" big.prm >big.log 2>big.err
code=$?
cat big.err
[ $code -eq 1 ] || fail "exit code $code, expected 1"
if [ -n "$launch" ]; then
  grep '^knee_contact: ' big.err >said.err
else
  cp big.err said.err
fi
[ "$(wc -l <said.err)" -eq 1 ] || fail "the program did not say one line"
grep -q "no space left on the device" said.err || fail "the message does not say the disk is full"
grep -q "(rank " said.err && fail "a rank was left waiting and ended by MPI_Abort"
(cd disk/out && md5sum -- * | sort) | cmp -s - before.md5 || fail "the previous result set changed"
[ "$(ls -A disk)" = "out" ] || fail "left in the folder's parent: $(ls -A disk)"
echo "PASS: full disk refused in one line; previous result set unchanged"
