#!/usr/bin/env bash
# The program draws its pictures when installed away from the build tree:
# cmake --install into a fresh prefix, then the installed binary runs SCENE
# from another folder with pictures on and must write deformation.png,
# stress_yy.png and contact_pressure.png without a warning.
# Usage: installed_build.sh BUILD_DIR SCENE
set -u
export LC_ALL=C
build=$1
scene=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log" 2>&1 ||
  { cat "$work/install.log"; echo "FAIL: cmake --install"; exit 1; }
sed -e "s|^  set Folder .*||" -e 's/^  set Write files .*//' -e 's/^  set Pictures .*//' \
  -e "s|= \(\.\./\)*prm/|= $(cd "$(dirname "$0")/../../prm" && pwd)/|" "$scene" >"$work/scene.prm"
printf 'subsection Output\n  set Folder = out\n  set Pictures = true\nend\n' >>"$work/scene.prm"
cd "$work"
"$work/prefix/bin/knee_contact" scene.prm >run.log 2>&1 || { tail -n 3 run.log; echo "FAIL: run"; exit 1; }
if grep -q "warning: no pictures" run.log; then grep warning run.log; echo "FAIL: no pictures"; exit 1; fi
for p in deformation stress_yy contact_pressure; do
  [ -s "out/$p.png" ] || { echo "FAIL: out/$p.png missing"; exit 1; }
done
echo "PASS: the installed program draws its pictures"
