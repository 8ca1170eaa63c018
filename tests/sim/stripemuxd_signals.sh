#!/usr/bin/env bash
# stripemuxd as a process: SIGTERM (and SIGINT) stop it cleanly with exit 0 and a last status
# line while a host is streaming; a bad board exits 2, bad usage 1.
#   stripemuxd_signals.sh STRIPEMUXD STRIPEMUX SOURCE_DIR SIGNAL
set -euo pipefail
daemon=$1 tool=$2 src=$3 signal=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

set +e
"$daemon" --board "$src/boards/no-such-board" >/dev/null 2>"$work/err"; code=$?
set -e
[ "$code" -eq 2 ] || { echo "missing board: exit $code, expected 2"; exit 1; }
grep -q "no-such-board" "$work/err" || { echo "missing board not named"; exit 1; }
set +e
"$daemon" --port 80000 >/dev/null 2>&1; code=$?
set -e
[ "$code" -eq 1 ] || { echo "bad usage: exit $code, expected 1"; exit 1; }

"$tool" sim --rig "$src/boards/sim/rig_2proj_2cam.json" --scene plane --no-truth --out "$work/frames" >/dev/null
mv "$work/frames/cam0.png" "$work/frames/cam0_0.png"
mv "$work/frames/cam1.png" "$work/frames/cam1_0.png"
"$daemon" --board "$src/boards/sim" --replay "$work/frames" --port 0 >"$work/log" 2>&1 &
pid=$!
for _ in $(seq 1 100); do
  grep -q "^listening on" "$work/log" && break
  sleep 0.1
done
port=$(sed -n 's/^listening on [0-9.]*:\([0-9]*\)$/\1/p' "$work/log")
[ -n "$port" ] || { cat "$work/log"; echo "stripemuxd did not listen"; exit 1; }
# A host streams for a while; the signal arrives mid-stream.
"$tool" stream --device "127.0.0.1:$port" --frames 1000 --timeout 60 --no-ply --out "$work/out" \
  >/dev/null 2>&1 &
host=$!
sleep 3
kill "-$signal" "$pid"
set +e
wait "$pid"; code=$?
set -e
kill "$host" 2>/dev/null || true
[ "$code" -eq 0 ] || { cat "$work/log"; echo "exit $code after SIG$signal, expected 0"; exit 1; }
grep -q "^stopped: captured [1-9]" "$work/log" || { cat "$work/log"; echo "no final counters"; exit 1; }
echo "SIG$signal: stopped cleanly: $(tail -n 1 "$work/log")"
