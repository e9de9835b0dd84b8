#!/usr/bin/env bash
# A full disk during output: the output folder lies on a small tmpfs (200 kB;
# uniaxial_block writes 16 kB, knee_small 350 kB) that
# holds SMALL's result set but not BIG's. The run of BIG must exit 1 with
# one line that says the device is full, leave SMALL's result set unchanged
# and leave no staging folder. Needs root to mount the tmpfs; skipped
# (exit 77) otherwise. Usage: full_disk.sh PROGRAM SMALL BIG
set -u
export LC_ALL=C
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
"$program" big.prm >big.log 2>big.err
code=$?
cat big.err
[ $code -eq 1 ] || fail "exit code $code, expected 1"
[ "$(wc -l <big.err)" -eq 1 ] || fail "stderr is not one line"
grep -q "no space left on the device" big.err || fail "the message does not say the disk is full"
(cd disk/out && md5sum -- * | sort) | cmp -s - before.md5 || fail "the previous result set changed"
[ "$(ls -A disk)" = "out" ] || fail "left in the folder's parent: $(ls -A disk)"
echo "PASS: full disk refused in one line; previous result set unchanged"
