#!/usr/bin/env bash
# The host tool installed (cmake --install --strip) into a temporary prefix and run from a folder
# outside the source and build trees: pattern, sim of a named scene, decode (depth checked against
# the render's truth) and eval find the installed data beside the executable. With the data moved
# away the tool must fail (nothing found elsewhere: no source path inside), and
# STRIPEMUX_DATA_DIR must lead it to the moved data.
#   install_test.sh CMAKE BUILD_DIR SOURCE_DIR DEPTH_CHECK
set -euo pipefail
cmake=$1 build=$2 src=$3 depth_check=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/root/usr
fail() {
  echo "install_test: $*" >&2
  exit 1
}

"$cmake" --install "$build" --prefix "$prefix" --component stripemux --strip >"$work/install.log"
tool=$prefix/bin/stripemux
data=$prefix/share/stripemux
rig=$data/boards/sim/rig_2proj_1cam.json
[ -x "$tool" ] || fail "no executable $tool"
for f in "$rig" "$data/scenes/plane.json" "$data/scenes/meshes/bun_zipper.ply"; do
  [ -f "$f" ] || fail "not installed: $f"
done
for dir in "$src" "$build"; do
  ! grep -aqF "$(realpath "$dir")" "$tool" || fail "$tool names $dir"
done

# Every run: a fresh folder outside both trees, no override of the data folder.
mkdir "$work/run"
cd "$work/run"
run() {
  env -u STRIPEMUX_DATA_DIR -u STRIPEMUX_SCENES "$@"
}

run "$tool" pattern --rig "$rig" --out pattern >/dev/null
for p in proj0 proj1; do
  [ "$(head -c 8 "pattern/$p.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] ||
    fail "pattern/$p.png is not a PNG"
done

run "$tool" sim --rig "$rig" --scene plane --out frame >/dev/null
run "$tool" decode --rig "$rig" --image cam0=frame/cam0.png --out decoded >/dev/null
unit=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["depth_unit_m"])' \
  decoded/meta.json)
"$depth_check" decoded/cam0.depth.png frame/cam0.depth.pfm "$unit" 0.8

# eval reads the example rigs and scenes through the evaluation library's own look-up.
run "$tool" eval --out eval --only scenes --scene plane --supersampling 1 >/dev/null
grep -q plane eval/results.md || fail "eval/results.md does not mention the plane"

# Data moved away: the named scene is not found, and the message says how to point at it.
mv "$data" "$work/moved"
set +e
run "$tool" sim --rig "$work/moved/boards/sim/rig_2proj_1cam.json" --scene plane --out lost \
  >/dev/null 2>"$work/err"
code=$?
set -e
[ "$code" -ne 0 ] || fail "sim found a named scene with the data moved away"
grep -q STRIPEMUX_DATA_DIR "$work/err" || fail "no hint at STRIPEMUX_DATA_DIR: $(cat "$work/err")"
# Scenes pointed at, example rigs not: eval must find the rigs nowhere else (a source tree).
set +e
env -u STRIPEMUX_DATA_DIR STRIPEMUX_SCENES="$work/moved/scenes" "$tool" eval --out lost-eval \
  --only scenes --scene plane --supersampling 1 >/dev/null 2>"$work/err"
code=$?
set -e
[ "$code" -ne 0 ] || fail "eval found the example rigs with the data moved away"
grep -q STRIPEMUX_DATA_DIR "$work/err" || fail "no hint at STRIPEMUX_DATA_DIR: $(cat "$work/err")"
STRIPEMUX_DATA_DIR=$work/moved "$tool" sim --rig "$work/moved/boards/sim/rig_2proj_1cam.json" \
  --scene plane --out found >/dev/null
[ -f found/cam0.png ] || fail "STRIPEMUX_DATA_DIR: no render"
echo "install_test: installed tool ran from $work/run"
