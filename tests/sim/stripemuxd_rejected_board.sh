#!/usr/bin/env bash
# stripemuxd refuses a board it cannot run with exit 2 (docs/firmware.md) and a message naming
# the field: a rig with more projectors than the method separates, cameras of different sizes.
#   stripemuxd_rejected_board.sh STRIPEMUXD SOURCE_DIR
set -euo pipefail
daemon=$1 src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# variant NAME PYTHON: boards/sim with its rig and board.json edited by PYTHON (rig, board given).
variant() {
  mkdir -p "$work/$1"
  python3 - "$src/boards/sim" "$work/$1" <<PY
import json, sys
src, dst = sys.argv[1], sys.argv[2]
board = json.load(open(src + "/board.json"))
rig = json.load(open(src + "/" + board["rig"]))
$2
board["rig"] = "rig.json"
json.dump(rig, open(dst + "/rig.json", "w"))
json.dump(board, open(dst + "/board.json", "w"))
PY
}

variant four_projectors '
for i in (2, 3):
    p = dict(rig["projectors"][i % 2]); p["id"] = "proj%d" % i; rig["projectors"].append(p)
    board["triggers"]["lines"].append({"role": "proj%d" % i, "chip": "sim", "line": i})'
variant mixed_sizes '
rig["cameras"][1]["width"] = 800; rig["cameras"][1]["K"][2] = 399.5'

check() {
  set +e
  "$daemon" --board "$work/$1" --port 0 >/dev/null 2>"$work/err"; code=$?
  set -e
  [ "$code" -eq 2 ] || { cat "$work/err"; echo "$1: exit $code, expected 2"; exit 1; }
  grep -q "$2" "$work/err" || { cat "$work/err"; echo "$1: the message lacks '$2'"; exit 1; }
  echo "$1: exit 2: $(cat "$work/err")"
}
check four_projectors 'projectors: at most 3 projectors'
check mixed_sizes 'rig: the cameras of a board share one image size'
