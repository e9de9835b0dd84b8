#!/usr/bin/env bash
# Which code CI's sanitizer stage runs: builds the project with gcov
# instrumentation (--coverage, into BUILD), runs the tests labelled
# "sanitizer" there, and prints per source file the lines it executed (gcov's
# count of lines with code). Fails if a source file under source/ executed
# none. Not a ctest test: it builds the whole project once more (about 4
# minutes on 2 cores) and runs the sanitizer set (3 to 6 minutes).
# Usage: tests/drivers/sanitizer_coverage.sh [BUILD]   (default build-coverage)
set -euo pipefail
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$source_dir/build-coverage}
mkdir -p "$build"
build=$(cd "$build" && pwd)
cmake -S "$source_dir" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS=--coverage -DCMAKE_EXE_LINKER_FLAGS=--coverage \
  >"$build/configure.log"
cmake --build "$build" -j2 >"$build/build.log"
find "$build" -name '*.gcda' -delete
ctest --test-dir "$build" -j2 -L sanitizer --output-on-failure \
  >"$build/ctest.log" || { tail -n 30 "$build/ctest.log"; exit 1; }
tail -n 3 "$build/ctest.log"

# One gcov run per object file of the library and the program; each source
# file's own lines only (not the headers it includes).
cd "$build"
report=$build/coverage.txt
: >"$report"
find "$build/CMakeFiles" -name '*.gcno' | while read -r note; do
  gcov -n -o "$note" "${note%.gcno}.o" 2>/dev/null |
    awk -v root="$source_dir/source/" '
      /^File / { file = $2; gsub("\047", "", file) }
      /^Lines executed:/ && index(file, root) == 1 {
        split($2, p, ":"); sub("%", "", p[2]);
        printf "%s %s %s\n", substr(file, length(root) + 1), p[2], $4 }' \
      >>"$report"
done
sort -u "$report" -o "$report"
printf '%-40s %8s %6s\n' "source file" "executed" "lines"
missing=0
while read -r file percent lines; do
  printf '%-40s %7s%% %6s\n' "$file" "$percent" "$lines"
done <"$report"
for file in $(cd "$source_dir/source" && find . -name '*.cc' | sed 's|^\./||'); do
  executed=$(awk -v f="$file" '$1 == f && $2 + 0 > 0' "$report")
  if [ -z "$executed" ]; then
    echo "NOT RUN under the sanitizer label: source/$file"
    missing=1
  fi
done
exit $missing
