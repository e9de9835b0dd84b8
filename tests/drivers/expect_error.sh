#!/usr/bin/env bash
# Runs "knee_contact FILE" on a bad input and passes only if the program exits
# non-zero without crashing (exit code < 128: no abort, no segfault), prints
# exactly one line on stderr, and that line matches the regular expression
# REGEX, by default the one on FILE's first line ("# expect: <regex>"); a
# line "# exit code: N" in FILE asks for that exit code.
# Usage: expect_error.sh PROGRAM FILE [REGEX]
set -u
export LC_ALL=C
program=$1
file=$2
regex=${3:-$(head -n 1 "$file" 2>/dev/null | sed -n 's/^# expect: //p')}
[ -n "$regex" ] || { echo "no '# expect: ' line in $file"; exit 1; }
workdir=$(mktemp -d)
trap 'rm -rf "$workdir"' EXIT
cd "$workdir"
if [ -n "$file" ]; then
  "$program" "$file" >stdout 2>stderr
else
  "$program" >stdout 2>stderr
fi
code=$?
echo "exit code $code; stderr:"
cat stderr
if [ $code -eq 0 ] || [ $code -ge 128 ]; then
  echo "FAIL: expected a non-zero exit code below 128"
  exit 1
fi
expected_code=$(sed -n 's/^# exit code: //p' "$file" 2>/dev/null | head -n 1)
if [ -n "$expected_code" ] && [ "$code" -ne "$expected_code" ]; then
  echo "FAIL: expected exit code $expected_code"
  exit 1
fi
if [ "$(wc -l <stderr)" -ne 1 ]; then
  echo "FAIL: expected exactly one line on stderr"
  exit 1
fi
if ! grep -aEq -- "$regex" stderr; then
  echo "FAIL: stderr does not match '$regex'"
  exit 1
fi
echo PASS
