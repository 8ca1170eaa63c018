#!/usr/bin/env bash
# The Debian packages of a built tree (CPack): each has its name, the build's architecture,
# Depends from the libraries it links, and its files; unpacked (dpkg -x) into a temporary root,
# the firmware runs (under the emulator in a cross build) and the systemd unit starts a binary of
# the package. With the host tool's package, the unpacked tool renders a named scene.
#   deb_test.sh CPACK BUILD_DIR ARCH HOST_TOOL(0|1) [EMULATOR...]
set -euo pipefail
cpack=$1 build=$2 arch=$3 host_tool=$4
shift 4
emulator=("$@")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() {
  echo "deb_test: $*" >&2
  exit 1
}

"$cpack" --config "$build/CPackConfig.cmake" -B "$work/packages" >"$work/cpack.log" ||
  fail "cpack failed: $(cat "$work/cpack.log")"

# check_deb NAME FILE...: the package's fields and that it holds every FILE; unpacks it.
check_deb() {
  local name=$1 deb
  shift
  deb=$(echo "$work/packages/${name}_"*"_$arch.deb")
  [ -f "$deb" ] || fail "no ${name}_*_$arch.deb: $(ls "$work/packages")"
  [ "$(dpkg-deb -f "$deb" Package)" = "$name" ] || fail "$deb: Package is not $name"
  [ "$(dpkg-deb -f "$deb" Architecture)" = "$arch" ] || fail "$deb: Architecture is not $arch"
  dpkg-deb -f "$deb" Depends | grep -q 'libc6 (>=' || fail "$deb: Depends lacks libc6"
  dpkg-deb -f "$deb" Depends | grep -q 'libstdc++6 (>=' || fail "$deb: Depends lacks libstdc++6"
  dpkg-deb -c "$deb" | awk '{print $6}' >"$work/$name.files"
  for f in "$@"; do
    grep -qx "\./$f" "$work/$name.files" || fail "$deb lacks /$f"
  done
  dpkg -x "$deb" "$work/root"
  echo "deb_test: $(basename "$deb"): Depends: $(dpkg-deb -f "$deb" Depends)"
}

unit=usr/lib/systemd/system/stripemuxd.service
check_deb stripemuxd usr/bin/stripemuxd "$unit" usr/share/stripemuxd/boards/rpi4/board.json \
  usr/share/stripemuxd/boards/rpi4/rig.json
root=$work/root
grep -qx 'Restart=on-failure' "$root/$unit" || fail "$unit: no Restart=on-failure"
exe=$(sed -n 's/^ExecStart=\([^ ]*\) --board .*/\1/p' "$root/$unit")
board=$(sed -n 's/^Environment=STRIPEMUXD_BOARD=//p' "$root/$unit")
[ -x "$root$exe" ] || fail "$unit starts $exe, which the package lacks"
[ -f "$root$board/board.json" ] || fail "$unit names board $board, which the package lacks"
version=$("${emulator[@]}" "$root$exe" --version)
[ -n "$version" ] || fail "$exe --version printed nothing"
"${emulator[@]}" "$root/usr/bin/stripemuxd" --version >/dev/null
echo "deb_test: $unit starts $exe (version $version) on $board"

if [ "$host_tool" -eq 1 ]; then
  share=usr/share/stripemux
  check_deb stripemux usr/bin/stripemux "$share/scenes/plane.json" \
    "$share/scenes/meshes/bun_zipper.ply" "$share/boards/sim/rig_2proj_1cam.json"
  mkdir "$work/run"
  cd "$work/run"
  env -u STRIPEMUX_DATA_DIR -u STRIPEMUX_SCENES "$root/usr/bin/stripemux" sim \
    --rig "$root/$share/boards/sim/rig_2proj_1cam.json" --scene plane --out frame \
    >/dev/null
  for f in frame/cam0.png frame/cam0.depth.pfm; do
    [ -f "$f" ] || fail "the unpacked tool did not write $f"
  done
  echo "deb_test: the unpacked stripemux rendered the named scene plane"
fi
