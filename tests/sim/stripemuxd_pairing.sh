#!/usr/bin/env bash
# The owner's channel on stripemuxd as a process (docs/security.md): with --state, a host that
# never paired is refused for stream, config and capture (exit code and message); a wrong code
# is refused; the right code pairs; then streaming and config set work, and a relay that records
# the bytes between host and device never sees the settings or the protocol's magic in the clear;
# a second host (another XDG_CONFIG_HOME) is refused, and a host busy message names no address.
#   stripemuxd_pairing.sh STRIPEMUXD STRIPEMUX SOURCE_DIR
set -euo pipefail
daemon=$1 tool=$2 src=$3
work=$(mktemp -d)
pid="" relay=""
trap '[ -z "$pid" ] || kill -9 "$pid" 2>/dev/null || true
      [ -z "$relay" ] || kill "$relay" 2>/dev/null || true; rm -rf "$work"' EXIT
mkdir "$work/state"
export XDG_CONFIG_HOME=$work/host1

fail() {
  cat "$work/log"
  echo "FAIL: $*"
  exit 1
}

"$daemon" --board "$src/boards/sim" --port 0 --fps 5 --state "$work/state" >"$work/log" 2>&1 &
pid=$!
for _ in $(seq 1 200); do
  grep -q "^settings: " "$work/log" && break
  sleep 0.05
done
port=$(sed -n 's/^listening on [0-9.]*:\([0-9]*\)$/\1/p' "$work/log")
[ -n "$port" ] || fail "stripemuxd did not start"
[ "$(stat -c %a "$work/state/identity.key")" = 600 ] || fail "identity.key is not 0600"
code=$(sed -n 's/^pairing code: \([0-9]\{8\}\) .*/\1/p' "$work/log")
[ -n "$code" ] || fail "no pairing code printed at the first start"

# Everything the host tool sends goes through the recording relay.
python3 "$src/tests/sim/tcp_relay.py" "$port" "$work/relay_port" "$work/wire" &
relay=$!
for _ in $(seq 1 100); do
  [ -s "$work/relay_port" ] && break
  sleep 0.05
done
device=127.0.0.1:$(cat "$work/relay_port")

# Runs the tool expecting exit code $1; its stderr must contain $2.
refused() {
  local want=$1 text=$2
  shift 2
  set +e
  "$tool" "$@" >"$work/out" 2>"$work/err"
  local got=$?
  set -e
  [ "$got" = "$want" ] || fail "$*: exit $got, not $want: $(cat "$work/err")"
  grep -qF -- "$text" "$work/err" || fail "$*: no \"$text\" in: $(cat "$work/err")"
}

hint="not paired with the device, which serves its owner's hosts only: run stripemux pair --device $device"
refused 3 "$hint" stream --device "$device" --frames 1 --out "$work/s0"
refused 3 "$hint" config --device "$device" get fps
refused 3 "$hint" capture --device "$device" --out "$work/c0"
if [ -d "$work/s0" ] && [ -n "$(ls -A "$work/s0")" ]; then fail "a refused stream wrote frames"; fi

wrong=$(printf '%08d' $(((10#$code + 1) % 100000000)))
refused 2 "wrong code, 2 attempts left" pair --device "$device" --code "$wrong"
grep -q "pairing: a wrong code (2 attempts left)" "$work/log" || fail "the device did not say"
"$tool" pair --device "$device" --code "$code" >"$work/out" 2>&1 || fail "pair: $(cat "$work/out")"
grep -q "^paired with $device" "$work/out" || fail "pair did not say so: $(cat "$work/out")"
ls "$work/state/hosts/"host-*.pub >/dev/null || fail "the device stored no host key"
refused 2 "pairing is closed" pair --device "$device" --code "$code"  # the code is used up

# Paired: the same commands work, encrypted.
"$tool" stream --device "$device" --frames 2 --timeout 30 --out "$work/s1" >/dev/null ||
  fail "stream after pairing"
ls "$work"/s1/cam0*.ply >/dev/null || fail "no frames streamed after pairing"
"$tool" config --device "$device" set depth_max_m=3.25 confidence_min=41 >"$work/out" ||
  fail "config set after pairing: $(cat "$work/out")"
for _ in $(seq 1 200); do
  [ "$(grep -c "^settings: " "$work/log")" -ge 2 ] && break
  sleep 0.05
done
[ "$("$tool" config --device "$device" get depth_max_m)" = 3.25 ] || fail "config get"
grep -q '"depth_max_m": 3.25' "$work/state/config.json" || fail "not stored"

# The eavesdropper's view: settings text, rig JSON and the framing's magic after the
# handshakes never appear; the handshake messages themselves do (they are clear by design).
for secret in depth_max_m confidence_min stripemux-config stripemux-rig '"cameras"'; do
  ! grep -qaF "$secret" "$work/wire" || fail "\"$secret\" crossed the network in the clear"
done
grep -qaF "not paired" "$work/wire" || fail "the relay recorded nothing (refusals are clear)"

# Another host on this machine (own keys) is refused, also after asking to pair.
XDG_CONFIG_HOME=$work/host2 refused 3 "run stripemux pair" config --device "$device" get fps
XDG_CONFIG_HOME=$work/host2 refused 2 "pairing is closed" pair --device "$device" --code "$code"

# While the paired host streams, another is told the device is busy, but not by whom.
"$tool" stream --device "$device" --frames 40 --timeout 60 --out "$work/s2" >/dev/null 2>&1 &
streamer=$!
for _ in $(seq 1 100); do
  [ -n "$(ls -A "$work/s2" 2>/dev/null)" ] && break
  sleep 0.1
done
XDG_CONFIG_HOME=$work/host2 refused 3 "the device is busy, held by another host" \
  config --device "$device" get fps
! grep -q "held by [0-9[]" "$work/err" || fail "the busy error names the holder: $(cat "$work/err")"
kill "$streamer" 2>/dev/null || true
wait "$streamer" 2>/dev/null || true

# A hand-dropped key makes it a paired host (the owner's way), once it pairs its side too.
XDG_CONFIG_HOME=$work/host2 "$tool" pair --show-key >"$work/state/hosts/laptop.pub"
grep -q "^smx-x25519 [0-9a-f]\{64\} " "$work/state/hosts/laptop.pub" || fail "--show-key format"

kill -TERM "$pid"
wait "$pid" || fail "stripemuxd did not stop cleanly"
pid=""
echo "ok: pairing, refusals and the encrypted channel"
