#!/usr/bin/env bash
# Regenerate tests/scenes/<name>.output and tests/unit/<name>.output from fresh
# runs of the tests matching REGEX and show what changed, for review (as
# ASPECT's script does). A reference changes only with a reason in the commit
# message. Usage: tests/drivers/generate_reference_output.sh [regex]
set -u
shopt -s nullglob
cd "$(dirname "$0")/../.."
for source in tests/scenes/*.prm tests/scenes/*.json tests/unit/*.cc; do
  [ -f "${source%.*}.output" ] || touch "${source%.*}.output"
done
start=$(mktemp)
trap 'rm -f "$start"' EXIT
cmake build >/dev/null
ctest --test-dir build -j2 -R "${1:-.}" >/dev/null
# Only what this call's tests wrote (a result folder of an earlier run would
# otherwise bring back stale output).
for run in build/tests/scenes/*.release build/tests/unit/*.release; do
  name=$(basename "$run" .release)
  kind=$(basename "$(dirname "$run")")
  for result in "$run/output" "$run/failing_output"; do
    [ "$result" -nt "$start" ] && cp "$result" "tests/$kind/$name.output"
  done
done
git --no-pager diff --stat -- 'tests/*.output'
git status --short -- 'tests/*.output'
