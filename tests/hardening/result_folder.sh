#!/usr/bin/env bash
# Output/Folder as users set it up: a symbolic link to their results folder
# (relative and absolute, a chain of two, dangling), a read-only result
# folder, a link that leads round in a circle. Required:
# - through a link, the new result set replaces the old one at the link's
#   target, the link stays a link, and nothing is left beside link or
#   target (no staging folder, no lock);
# - a read-only result folder is refused with one line and exit 1, its
#   files unchanged; a circular link likewise.
# Usage: result_folder.sh PROGRAM SCENE (a scene that runs in a second).
set -u
export LC_ALL=C
program=$1
scene=$2
work=$(mktemp -d)
trap 'chmod -R u+w "$work"; rm -rf "$work"' EXIT
cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
# scene_in FOLDER: the scene writing into FOLDER, without pictures.
scene_in() {
  sed -e "s|^  set Folder .*||" -e 's/^  set Write files .*//' \
    -e 's/^  set Terminal .*//' -e 's/^  set Pictures .*//' "$scene"
  printf 'subsection Output\n  set Folder = %s\n  set Pictures = false\nend\n' "$1"
}
nothing_beside() { # nothing_beside FOLDER...: no staging folder, no lock
  for f in "$@"; do
    local left
    left=$(ls -A "$(dirname "$f")" | grep -F ".$(basename "$f")." || true)
    [ -z "$left" ] || fail "left beside $f: $left"
  done
}

mkdir -p data
scene_in data/run7 >direct.prm
"$program" direct.prm >direct.log 2>&1 || fail "the direct run failed"
[ -f data/run7/summary.json ] || fail "no result set in data/run7"
touch -d '2000-01-01' data/run7/summary.json

for kind in relative absolute chain; do
  rm -f results link2
  case $kind in
  relative) ln -s data/run7 results ;;
  absolute) ln -s "$work/data/run7" results ;;
  chain) ln -s data/run7 link2 && ln -s link2 results ;;
  esac
  scene_in results >link.prm
  "$program" link.prm >link.log 2>link.err || fail "$kind link: the run failed: $(cat link.err)"
  [ -L results ] || fail "$kind link: results is no longer a symbolic link"
  [ "$(readlink -f results)" = "$work/data/run7" ] || fail "$kind link: the link points elsewhere"
  [ -f data/run7/summary.json ] || fail "$kind link: no result set at the target"
  [ data/run7/summary.json -nt direct.prm ] || fail "$kind link: the target's result set is the old one"
  nothing_beside results data/run7
  touch -d '2000-01-01' data/run7/summary.json
  echo "PASS: a $kind link: the set replaced at its target, the link kept, nothing left"
done

# A dangling link: the target is created.
rm -f results && ln -s data/run8 results
scene_in results >dangling.prm
"$program" dangling.prm >dangling.log 2>&1 || fail "dangling link: the run failed"
[ -L results ] && [ -f data/run8/summary.json ] || fail "dangling link: no set at the target"
nothing_beside results data/run8
echo "PASS: a dangling link: the set written at its target"

# expect_refusal SCENE REGEX WHAT
expect_refusal() {
  "$program" "$1" >refused.log 2>refused.err
  local code=$?
  [ $code -eq 1 ] || fail "$3: exit code $code, expected 1"
  [ "$(wc -l <refused.err)" -eq 1 ] || fail "$3: stderr is not one line: $(cat refused.err)"
  grep -Eq "$2" refused.err || fail "$3: unexpected message: $(cat refused.err)"
  echo "PASS: $3: $(cat refused.err)"
}

# A read-only result folder (also for root, who may write anyway).
(cd data/run7 && md5sum -- * | sort) >before.md5
chmod a-w data/run7
scene_in data/run7 >readonly.prm
expect_refusal readonly.prm "Output/Folder: 'data/run7' is read-only" "a read-only result folder"
(cd data/run7 && md5sum -- * | sort) | cmp -s - before.md5 || fail "read-only: the files changed"
nothing_beside data/run7
chmod u+w data/run7

rm -f results && ln -s loop results && ln -s results loop
scene_in results >loop.prm
expect_refusal loop.prm "Output/Folder: 'results' is a symbolic link that leads round in a circle" "a circular link"
