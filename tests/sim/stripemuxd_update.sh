#!/usr/bin/env bash
# Firmware updates through `stripemuxd --supervise` (docs/update.md): a signed bundle of the
# build's own stripemuxd and boards/sim as 0.2.0 is installed and runs; a firmware that fails
# its self-test (exits, or never marks itself good) is rolled back with the reason; bundles that
# are cut, corrupted, signed by an unknown key, for another board or older are refused over the
# wire and nothing under slots/ or active changes. Then the crash matrix: SIGKILL at every step
# of an update (the daemon's, and the supervisor's around a trial and a rollback); after a
# restart the supervisor runs a whole signed firmware, old or new, and config.json is intact.
#   stripemuxd_update.sh STRIPEMUXD STRIPEMUX SOURCE_DIR
set -euo pipefail
daemon=$1 tool=$2 src=$3
work=$(mktemp -d)
sup=""
trap '[ -z "$sup" ] || kill -9 "$sup" 2>/dev/null || true; rm -rf "$work"' EXIT
state=$work/state

fail() {
  [ ! -f "$work/log" ] || tail -n 40 "$work/log"
  echo "FAIL: $*"
  exit 1
}

port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
device=127.0.0.1:$port

"$tool" sim --rig "$src/boards/sim/rig_2proj_2cam.json" --scene plane --no-truth \
  --out "$work/frames" >/dev/null
mv "$work/frames/cam0.png" "$work/frames/cam0_0.png"
mv "$work/frames/cam1.png" "$work/frames/cam1_0.png"

# Keys: the device trusts "test"; "other" is a stranger.
"$tool" keygen --out "$work/test" >/dev/null
"$tool" keygen --out "$work/other" >/dev/null

# Firmware trees: the build's daemon, one that exits at once, one that never marks itself good.
firmware() {  # NAME BINARY
  mkdir -p "$work/$1/bin" "$work/$1/boards"
  cp -r "$src/boards/sim" "$work/$1/boards/sim"
  cp "$2" "$work/$1/bin/stripemuxd"
  chmod 755 "$work/$1/bin/stripemuxd"
}
firmware good "$daemon"
printf '#!/bin/sh\necho "broken firmware"\nexit 1\n' >"$work/exits.sh"
printf '#!/bin/sh\nexec sleep 600\n' >"$work/hangs.sh"
firmware exits "$work/exits.sh"
firmware hangs "$work/hangs.sh"
bundle() {  # OUT KEY FIRMWARE VERSION [bundle options]
  local out=$1 key=$2 fw=$3 version=$4
  shift 4
  "$tool" bundle --key "$work/$key.key" --firmware "$work/$fw" --out "$work/$out" \
    --version "$version" "$@" >/dev/null
}
bundle good.smxb test good 0.2.0
bundle exits.smxb test exits 0.3.0
bundle hangs.smxb test hangs 0.3.0
bundle stranger.smxb other good 0.2.0
bundle otherboard.smxb test good 0.2.0 --board othersim
bundle old.smxb test good 0.0.5
size=$(stat -c %s "$work/good.smxb")
# Cut: 4096 bytes of the middle gone (the header and the end are whole); corrupted: one byte.
head -c $((size / 2)) "$work/good.smxb" >"$work/cut.smxb"
tail -c $((size / 2 - 4096)) "$work/good.smxb" >>"$work/cut.smxb"
cp "$work/good.smxb" "$work/corrupt.smxb"
printf '\xff' | dd of="$work/corrupt.smxb" bs=1 seek=$((size / 2)) conv=notrunc status=none

# The state template: the trusted key and stored settings (fps 7).
mkdir -p "$work/template/keys"
cp "$work/test.pub" "$work/template/keys/test.pub"
printf '{\n  "format": "stripemux-config/1",\n  "fps": 7\n}\n' >"$work/template/config.json"
fresh_state() {
  rm -rf "$state"
  cp -a "$work/template" "$state"
}

start() {  # [VAR=value …]: the supervisor's environment
  : >"$work/log"
  env "$@" "$daemon" --supervise --trial-timeout 10 --board "$src/boards/sim" --state "$state" \
    --replay "$work/frames" --bind 127.0.0.1 --port "$port" --fps 5 >"$work/log" 2>&1 &
  sup=$!
}

stop() {
  kill -TERM "$sup" 2>/dev/null || true
  wait "$sup" 2>/dev/null || true
  sup=""
}

# The device's update status once it answers and no trial is under way.
settled() {
  local out
  for _ in $(seq 1 300); do
    if out=$("$tool" flash --device "$device" --status 2>/dev/null); then
      case $out in
        *"in slot"*) grep -q '"pending": ""' "$state/boot.json" 2>/dev/null || { sleep 0.1; continue; } ;;
      esac
      echo "$out"
      return 0
    fi
    sleep 0.1
  done
  fail "the device did not come back"
}

listing() {
  (cd "$state" && find slots active -printf '%p %s %l\n' 2>/dev/null | sort)
}

# The running firmware is whole: the active slot holds what the good bundle holds, or there is
# no active link and the factory firmware runs. Prints "old" or "new".
whole() {
  if [ -L "$state/active" ]; then
    cmp -s "$state/active/bin/stripemuxd" "$daemon" || fail "$1: the active slot's firmware differs"
    diff -r "$state/active/boards/sim" "$src/boards/sim" >/dev/null || fail "$1: boards differ"
    [ -f "$state/active/slot.json" ] || fail "$1: the active slot has no slot.json"
    echo new
  else
    echo old
  fi
}

config_intact() {
  cmp -s "$state/config.json" "$work/template/config.json" || fail "$1: config.json changed"
}

# The owner's channel: this host pairs once with the template's device identity, so every
# request below (flash, status, config) travels encrypted; an unpaired host is refused first.
export XDG_CONFIG_HOME=$work/host
fresh_state
start
for _ in $(seq 1 200); do
  grep -q "^pairing code: " "$work/log" && break
  sleep 0.05
done
code=$(sed -n 's/^pairing code: \([0-9]\{8\}\) .*/\1/p' "$work/log")
[ -n "$code" ] || fail "no pairing code printed"
set +e
"$tool" flash --device "$device" "$work/good.smxb" >/dev/null 2>"$work/err"; unpaired=$?
set -e
[ "$unpaired" -eq 3 ] && grep -q "not paired" "$work/err" ||
  fail "an unpaired host's flash: exit $unpaired, $(cat "$work/err")"
[ ! -e "$state/active" ] || fail "an unpaired host's flash changed the slots"
"$tool" pair --device "$device" --code "$code" >/dev/null || fail "pairing failed"
stop
rm -rf "$work/template"
cp -a "$state" "$work/template"
echo "unpaired host: flash refused; paired"

# 1. A good update: runs 0.2.0 in slot a, installed; the settings stay.
fresh_state
start
[ "$(settled)" = "no update; running 0.1.0 (the factory firmware)" ] || fail "factory status"
"$tool" flash --device "$device" "$work/good.smxb" >"$work/out" 2>"$work/err" ||
  fail "flash: $(cat "$work/err")"
grep -q "^device: verified 0.2.0 for board sim$" "$work/err" || fail "steps: $(cat "$work/err")"
[ "$(cat "$work/out")" = "installed 0.2.0; running 0.2.0 in slot a" ] ||
  fail "flash said: $(cat "$work/out")"
[ "$(whole good)" = new ] || fail "good: not running the new slot"
[ "$("$tool" config --device "$device" get fps)" = 7 ] || fail "the settings were lost"
grep -q "slot a: self-test passed, marked good" "$work/log" || fail "no self-test line"
config_intact good
echo "good update: installed, running 0.2.0 in slot a"

# 2. Failing firmware over the good one: rolled back to slot a with the reason.
rolled_back() {  # NAME WHY: flashing NAME.smxb ends in exit 4, rolled back to slot a for WHY
  local code
  set +e
  "$tool" flash --device "$device" "$work/$1.smxb" >"$work/out" 2>"$work/err"; code=$?
  set -e
  [ "$code" -eq 4 ] || fail "$1: flash exit $code: $(cat "$work/err")"
  grep -q "rolled back 0.3.0: $2; running 0.2.0 in slot a" "$work/err" ||
    fail "$1: $(cat "$work/err")"
}
rolled_back exits "the firmware exited with code 1 before marking itself good"
echo "firmware that exits: $(settled)"
rolled_back hangs "the firmware did not mark itself good within 10 s"
echo "firmware that never marks good: $(settled)"
config_intact rollback

# 3. Refused bundles: the reason, exit 2, slots/ and active unchanged, still running.
before=$(listing)
refuse() {  # FILE PATTERN
  set +e
  "$tool" flash --device "$device" "$work/$1" >/dev/null 2>"$work/err"; code=$?
  set -e
  [ "$code" -eq 2 ] || fail "$1: exit $code: $(cat "$work/err")"
  grep -q "$2" "$work/err" || fail "$1: no \"$2\" in: $(cat "$work/err")"
  [ "$(listing)" = "$before" ] || fail "$1: slots/ or active changed"
  echo "refused $1: $(sed -n 's/^stripemux flash: //p' "$work/err" | cut -c1-100)"
}
refuse cut.smxb "the device refused: "
refuse corrupt.smxb "the device refused: "
refuse stranger.smxb "the device refused: unknown key"
refuse otherboard.smxb "the device refused: wrong board"
refuse old.smxb "the device refused: downgrade"
head -c $((size - 10)) "$work/good.smxb" >"$work/short.smxb"
refuse short.smxb "SMXSIGN1) is missing"
mv "$state/keys" "$work/keys.away"
refuse good.smxb "this device trusts no key: install"
mv "$work/keys.away" "$state/keys"
[ "$(settled)" = "rolled back 0.3.0: the firmware did not mark itself good within 10 s; running 0.2.0 in slot a" ] ||
  fail "the status changed after refusals"
config_intact refusals
stop

# 4. The crash matrix, each from the factory firmware with a fresh state directory.
matrix() {  # POINT EXPECTED(old|new) [restart: the supervisor died]
  local point=$1 want=$2
  fresh_state
  start SMX_CRASH_AT="$point"
  settled >/dev/null
  "$tool" flash --device "$device" --wait 5 "$work/good.smxb" >/dev/null 2>"$work/err" || true
  if [ "${3:-}" = restart ]; then
    wait "$sup" 2>/dev/null || true
    sup=""
    start
  fi
  local status
  status=$(settled)
  local got
  got=$(whole "$point")
  [ "$got" = "$want" ] || fail "crash at $point: runs the $got firmware, expected $want ($status)"
  case $got in
    new) [ "$status" = "installed 0.2.0; running 0.2.0 in slot a" ] || fail "$point: $status" ;;
    old) case $status in *"running 0.1.0 (the factory firmware)") ;; *) fail "$point: $status" ;; esac ;;
  esac
  config_intact "$point"
  printf '%-30s %-4s %s\n' "$point" "$got" "$status"
  stop
}
echo "crash point                    runs update-status"
for point in received verified slot-written slot-synced pending-recorded; do
  matrix "update.$point" old
done
matrix update.switched new
matrix update.first-start old
matrix update.before-mark-good old
matrix supervise.trial-started old restart
# A rollback interrupted after its switch: the firmware before runs.
fresh_state
start SMX_CRASH_AT=supervise.rollback-switched
settled >/dev/null
"$tool" flash --device "$device" --wait 5 "$work/exits.smxb" >/dev/null 2>&1 || true
wait "$sup" 2>/dev/null || true
sup=""
start
status=$(settled)
[ "$(whole rollback-switched)" = old ] || fail "rollback-switched: not the old firmware"
case $status in rolled\ back*"running 0.1.0 (the factory firmware)") ;; *) fail "rollback-switched: $status" ;; esac
config_intact rollback-switched
printf '%-30s %-4s %s\n' supervise.rollback-switched old "$status"
stop
echo "updates: installed, rolled back, refused, and whole after a crash at every step"
