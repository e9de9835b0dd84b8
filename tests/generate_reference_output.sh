#!/usr/bin/env bash
# Regenerate tests/<name>.output from fresh runs and show what changed, for
# review (as ASPECT's script does). A reference changes only with a reason in
# the commit message. Usage: tests/generate_reference_output.sh [regex]
set -u
shopt -s nullglob
cd "$(dirname "$0")/.."
for source in tests/*.prm tests/*.json tests/*.cc; do
  name=$(basename "${source%.*}")
  case $name in *_scene | *_scene_*) continue ;; esac   # data for unit tests
  [ -f "tests/$name.output" ] || touch "tests/$name.output"
done
cmake build >/dev/null
ctest --test-dir build -j2 -R "${1:-.}" >/dev/null
for run in build/tests/*.release; do
  name=$(basename "$run" .release)
  for result in "$run/output" "$run/failing_output"; do
    [ -f "$result" ] && cp "$result" "tests/$name.output"
  done
done
git --no-pager diff --stat -- tests/*.output
git status --short -- 'tests/*.output'
