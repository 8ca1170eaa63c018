#!/usr/bin/env bash
# The owner's settings on stripemuxd as a process (docs/config.md): `stripemux config` changes
# them, they take effect (a depth window empties a plane's range image, and widening it brings
# the plane back), survive a restart, and bad values are refused naming the key with the stored
# file untouched. Then the crash matrix: the daemon is killed (SIGKILL) at every step of a
# settings write, and on restart it runs with the old settings or the new, whole, and says so.
#   stripemuxd_config.sh STRIPEMUXD STRIPEMUX SOURCE_DIR
set -euo pipefail
daemon=$1 tool=$2 src=$3
work=$(mktemp -d)
pid=""
trap '[ -z "$pid" ] || kill -9 "$pid" 2>/dev/null || true; rm -rf "$work"' EXIT
state=$work/state
mkdir "$state"

fail() {
  [ ! -f "$work/log" ] || cat "$work/log"
  echo "FAIL: $*"
  exit 1
}

# A plane 0.9 m from the cameras, replayed (no rendering while the daemon runs).
"$tool" sim --rig "$src/boards/sim/rig_2proj_2cam.json" --scene plane --no-truth \
  --out "$work/frames" >/dev/null
mv "$work/frames/cam0.png" "$work/frames/cam0_0.png"
mv "$work/frames/cam1.png" "$work/frames/cam1_0.png"

# Starts the daemon (extra environment as arguments) and waits for its settings line.
start() {
  : >"$work/log"
  env "$@" "$daemon" --board "$src/boards/sim" --replay "$work/frames" --port 0 --fps 5 \
    --state "$state" --open >"$work/log" 2>&1 &
  pid=$!
  for _ in $(seq 1 200); do
    grep -q "^settings: " "$work/log" && break
    sleep 0.05
  done
  port=$(sed -n 's/^listening on [0-9.]*:\([0-9]*\)$/\1/p' "$work/log")
  [ -n "$port" ] || fail "stripemuxd did not start"
  device=127.0.0.1:$port
}

stop() {
  kill -TERM "$pid"
  wait "$pid" || true
  pid=""
}

# Waits until the daemon has restarted with new settings (its n-th settings line).
await_settings() {
  for _ in $(seq 1 200); do
    [ "$(grep -c "^settings: " "$work/log")" -ge "$1" ] && return 0
    sleep 0.05
  done
  fail "the daemon did not restart with its new settings"
}

# Points in the point cloud of one streamed frame of cam0.
points() {
  rm -rf "$work/stream"
  "$tool" stream --device "$device" --frames 1 --timeout 30 --out "$work/stream" >/dev/null
  sed -n 's/^element vertex \([0-9]*\)$/\1/p' "$(ls "$work"/stream/cam0*.ply | head -n 1)"
}

start
[ "$(grep "^settings: " "$work/log")" = "settings: the board's" ] || fail "fresh state not said"
[ "$("$tool" config --device "$device" get fps)" = 5 ] || fail "get fps: not the board's 5"
full=$(points)
[ "$full" -gt 10000 ] || fail "the plane gave $full points"

# Nearer than the plane: nothing is left; the window takes effect after the restart.
"$tool" config --device "$device" set depth_max_m=0.5 confidence_min=40 fps=7 >"$work/out" ||
  fail "set refused: $(cat "$work/out")"
grep -q "^depth_max_m: 0.5$" "$work/out" || fail "set did not echo the settings"
await_settings 2
grep -q '"fps": 7' "$state/config.json" || fail "config.json does not hold fps 7"
[ "$(points)" -eq 0 ] || fail "depths beyond depth_max_m were sent"
"$tool" config --device "$device" set depth_max_m=2 >/dev/null
await_settings 3
windowed=$(points)
[ "$windowed" -gt 10000 ] || fail "depth_max_m 2 left $windowed points of the plane"

# Refused: the key is named, nothing stored changes, the daemon keeps running.
cp "$state/config.json" "$work/before.json"
set +e
"$tool" config --device "$device" set fps=500 >/dev/null 2>"$work/err"; code=$?
"$tool" config --device "$device" set exposure=3 >/dev/null 2>"$work/err2"; code2=$?
"$tool" config --device "$device" set exposure_us=5000 >/dev/null 2>"$work/err3"; code3=$?
set -e
[ "$code" -eq 2 ] && grep -q "fps: must be an integer from 1 to 120" "$work/err" ||
  fail "fps=500: exit $code, $(cat "$work/err")"
[ "$code2" -eq 1 ] && grep -q 'no setting "exposure"' "$work/err2" || fail "exposure: exit $code2"
# Replayed images cannot change their exposure: the board says it has no such control.
[ "$code3" -eq 2 ] && grep -q "exposure_us: the board's cameras have no exposure control" \
  "$work/err3" || fail "exposure_us=5000 on a replaying board: exit $code3, $(cat "$work/err3")"
cmp -s "$state/config.json" "$work/before.json" || fail "a refused change altered config.json"

# Kept across a restart.
stop
start
grep -q "^settings: $state/config.json (fps, depth_max_m, confidence_min)$" "$work/log" ||
  fail "the restarted daemon does not say it runs with the stored settings"
[ "$("$tool" config --device "$device" get fps)" = 7 ] || fail "fps not kept across a restart"
stop

# The crash matrix. Before the rename the old file is the settings; from it on, the new one.
for step in temp-created temp-written temp-synced renamed dir-synced; do
  start SMX_CRASH_AT="config.$step"
  set +e
  "$tool" config --device "$device" set fps=9 >/dev/null 2>&1
  wait "$pid"; code=$?
  set -e
  pid=""
  [ "$code" -eq 137 ] || fail "crash at config.$step: exit $code, expected 137 (SIGKILL)"
  start
  got=$("$tool" config --device "$device" get fps)
  case $step in
    temp-*) want=7 ;;
    *) want=9 ;;
  esac
  [ "$got" = "$want" ] || fail "crash at config.$step: fps $got after restart, expected $want"
  grep -q "^settings: $state/config.json (" "$work/log" || fail "crash at $step: settings lost"
  [ ! -e "$state/config.json.tmp" ] || fail "crash at $step: the temporary file stayed"
  case $step in
    temp-*) grep -q "^removed .*config.json.tmp" "$work/log" || fail "$step: leftover not said" ;;
  esac
  echo "crash at config.$step: restarted with fps $got ($([ "$want" = 7 ] && echo old || echo new))"
  "$tool" config --device "$device" set fps=7 >/dev/null
  await_settings 2
  stop
done

# One projector of two: frames where only proj1 is lit decode once the device decodes proj1 alone.
"$tool" sim --rig "$src/boards/sim/rig_2proj_2cam.json" --scene plane --no-truth --lit proj1 \
  --out "$work/proj1" >/dev/null
mv "$work/proj1/cam0.png" "$work/frames/cam0_0.png"
mv "$work/proj1/cam1.png" "$work/frames/cam1_0.png"
start
"$tool" config --device "$device" set projectors=proj1 >/dev/null
await_settings 2
alone=$(points)
[ "$alone" -gt 10000 ] || fail "projectors=proj1 gave $alone points of the plane lit by proj1"
stop

# reset drops every stored setting.
start
"$tool" config --device "$device" reset >/dev/null
await_settings 2
[ "$("$tool" config --device "$device" get fps)" = 5 ] || fail "reset kept fps"
stop
echo "settings: changed, applied, kept, refused, and whole after a crash at every step"
