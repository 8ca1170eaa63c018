#!/usr/bin/env bash
# `stripemux scan` against stripemuxd as a process (docs/scanning.md): a turntable scan and a
# hand-held scan end in a whole output folder, the table is turned back home, and scans the
# device cannot do are refused (exit 2, or 1 for bad usage) without leaving a model. The real
# daemon, because its own loop serves the turn requests (the in-process tests run theirs).
#   stripemuxd_scan.sh STRIPEMUXD STRIPEMUX SOURCE_DIR
set -euo pipefail
daemon=$1 tool=$2 src=$3
work=$(mktemp -d)
pid=""
trap '[ -z "$pid" ] || kill "$pid" 2>/dev/null || true; rm -rf "$work"' EXIT

fail() {
  [ ! -f "$work/log" ] || cat "$work/log"
  echo "FAIL: $*"
  exit 1
}

# Starts the daemon on a board folder and a free port; sets $device.
start() {
  : >"$work/log"
  "$daemon" --board "$1" --port 0 >"$work/log" 2>&1 &
  pid=$!
  for _ in $(seq 1 200); do
    grep -q "^listening on" "$work/log" && break
    sleep 0.05
  done
  port=$(sed -n 's/^listening on [0-9.]*:\([0-9]*\)$/\1/p' "$work/log")
  [ -n "$port" ] || fail "stripemuxd did not start on $1"
  device=127.0.0.1:$port
}

stop() {
  kill -TERM "$pid"
  wait "$pid" || true
  pid=""
}

# A JSON check: python3 EXPR over the file as `d`, true or the test fails with MESSAGE.
json_check() {
  python3 - "$1" "$2" <<'PY' || fail "$1: $3"
import json, sys
d = json.load(open(sys.argv[1]))
sys.exit(0 if eval(sys.argv[2]) else 1)
PY
}

nonempty() {
  for f in "$@"; do
    [ -s "$f" ] || fail "$f: missing or empty"
  done
}

# A sanitiser build decodes a frame in about a second: each frame gets two minutes, not ten seconds.
timeout=(--timeout 120)

# Turntable: six views 60° apart (to the step: 3200 steps a turn), each with depth and colour.
start "$src/boards/sim-turntable"
out=$work/turntable
"$tool" scan --device "$device" --turntable --views 6 --voxel 2 "${timeout[@]}" --out "$out" >"$work/scan" 2>&1 ||
  fail "scan --turntable: exit $?: $(cat "$work/scan")"
json_check "$out/rig.json" '"turntable" in d' 'no "turntable" axis'
json_check "$out/views/views.json" \
  'd["mode"] == "turntable" and len(d["views"]) == 6 and all(abs(v["turntable_deg"] - 60 * k) <= 0.1125 for k, v in enumerate(d["views"]))' \
  "not 6 views at 0, 60, ..., 300 degrees"
for id in $(python3 -c 'import json,sys; print(" ".join(v["id"] for v in json.load(open(sys.argv[1]))["views"]))' "$out/views/views.json"); do
  nonempty "$out/views/$id/cam0.depth.png" "$out/views/$id/cam0.colour.png"
done
nonempty "$out/model.ply" "$out/mesh.ply" "$out/mesh.obj" "$out/mesh.stl"
triangles=$(sed -n 's/^element face \([0-9]*\)\r\{0,1\}$/\1/p' "$out/mesh.ply")
[ "${triangles:-0}" -gt 1000 ] || fail "mesh.ply has ${triangles:-no} triangles"
stl=$(stat -c %s "$out/mesh.stl")
[ "$stl" -eq $((84 + 50 * triangles)) ] ||
  fail "mesh.stl is $stl bytes, not 84 + 50 x $triangles triangles of mesh.ply"
json_check "$out/report.json" 'd["placement"] == "turntable" and d["views_fused"] == 6' \
  "not placed by the turntable with 6 views fused"
"$tool" turntable --device "$device" >"$work/table" || fail "turntable status: exit $?"
grep -q "^angle: 0.000000 deg$" "$work/table" || fail "the table was not turned home: $(cat "$work/table")"
echo "turntable: 6 views, $triangles triangles, table back at 0"

# Without --turntable or --handheld: bad usage, before any connection.
set +e
"$tool" scan --device "$device" --out "$work/neither" >/dev/null 2>"$work/err"; code=$?
set -e
[ "$code" -eq 1 ] || fail "scan without a mode: exit $code, expected 1"
[ ! -e "$work/neither/model.ply" ] || fail "scan without a mode left a model"
set +e
"$tool" scan --device "$device" --turntable --timeout 0 --out "$work/no_time" >/dev/null 2>"$work/err"
code=$?
set -e
[ "$code" -eq 1 ] || fail "scan --timeout 0: exit $code, expected 1"
grep -q -- "--timeout" "$work/err" || fail "the usage error does not name --timeout: $(cat "$work/err")"
stop

# Hand-held: twelve captures tracked, with their poses.
start "$src/boards/sim-handheld"
out=$work/handheld
"$tool" scan --device "$device" --handheld --frames 12 --voxel 2 "${timeout[@]}" --out "$out" >"$work/scan" 2>&1 ||
  fail "scan --handheld: exit $?: $(cat "$work/scan")"
json_check "$out/views/views.json" \
  'd["mode"] == "handheld" and len(d["views"]) >= 2 and all(len(v["pose"]) == 16 for v in d["views"])' \
  "views without poses"
json_check "$out/report.json" '"tracking" in d and d["tracking"]["captures"] >= 12' \
  "no tracking of 12 captures"
nonempty "$out/model.ply" "$out/mesh.stl"
echo "handheld: $(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["views"]))' "$out/views/views.json") of 12 captures fused"
stop

# refused CODE PATTERN FOLDER: a turntable scan of the running device exits CODE saying PATTERN
# and leaves no model.
refused() {
  set +e
  "$tool" scan --device "$device" --turntable --views 6 --out "$3" >/dev/null 2>"$work/err"
  code=$?
  set -e
  [ "$code" -eq "$1" ] || fail "exit $code, expected $1: $(cat "$work/err")"
  grep -q -- "$2" "$work/err" || fail "the refusal does not say \"$2\": $(cat "$work/err")"
  [ ! -e "$3/model.ply" ] && [ ! -e "$3/mesh.stl" ] || fail "a refused scan left a model in $3"
  echo "refused: $(cat "$work/err")"
}

# A board without a turntable: refused, saying so and what to do instead.
start "$src/boards/sim"
refused 2 "no turntable" "$work/no_table"
grep -q -- "--handheld" "$work/err" || fail "the refusal does not name --handheld"
stop

# A turntable whose rig has no axis: refused, naming the calibration that finds it.
cp -r "$src/boards/sim-turntable" "$work/no_axis"
python3 - "$work/no_axis/rig.json" <<'PY'
import json, sys
rig = json.load(open(sys.argv[1]))
del rig["turntable"]
json.dump(rig, open(sys.argv[1], "w"))
PY
start "$work/no_axis"
refused 2 "calibrate --device $device --turntable" "$work/no_axis_scan"
stop
echo "scan: turntable and hand-held scans whole, refusals clean"
