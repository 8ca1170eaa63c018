# A firmware update on the qemu board, on the real network path: stripemuxd runs under its
# supervisor with a state directory (the owner's channel, a trusted key); the host pairs with
# the code the device prints, then `stripemux flash` uploads a signed bundle of the aarch64
# firmware as 0.2.0 over virtio-net. The device verifies it, writes the inactive slot, switches,
# and the supervisor starts the new firmware, which passes its self-test on vivid and gpio-sim
# and marks itself good. The host must see 0.2.0 running in slot a, and the guest's state must
# say so too.
# shellcheck source=tests/kernel/firmware_board.sh
. "$KERNEL_DIR/firmware_board.sh"

case_stage() {
  [ -n "$HOST_BUILD" ] || kernel_die "the update test needs --host-build (stripemux, png_to_ppm)"
  STRIPEMUX=$HOST_BUILD/tools/host/stripemux
  [ -x "$STRIPEMUX" ] || kernel_skip "no host stripemux in $HOST_BUILD (build the host preset first)"
  local rig=$SOURCE_DIR/boards/sim/rig_2proj_1cam.json
  stage_qemu_board "$rig"

  # The bundle: the guest's own firmware, stripped as a package ships it, and the board files.
  rm -rf "$WORK/fw" "$WORK/owner.key" "$WORK/owner.pub" "$WORK/host" "$WORK/fw.smxb"
  mkdir -p "$WORK/fw/bin" "$WORK/fw/boards/sim"
  local daemon=$BUILD/firmware/stripemuxd strip=strip
  [ "$KARCH" = aarch64 ] || daemon=$BUILD/firmware/stripemuxd-linux
  [ "$KARCH" = aarch64 ] && strip=aarch64-linux-gnu-strip
  "$strip" -o "$WORK/fw/bin/stripemuxd" "$daemon"
  cp -r "$SOURCE_DIR/boards/qemu" "$WORK/fw/boards/qemu"
  cp "$rig" "$WORK/fw/boards/sim/"
  "$STRIPEMUX" keygen --out "$WORK/owner" >/dev/null
  "$STRIPEMUX" bundle --key "$WORK/owner.key" --firmware "$WORK/fw" --out "$WORK/fw.smxb" \
    --version 0.2.0 --board qemu >/dev/null
  stage_file "$WORK/owner.pub" /state/keys/owner.pub

  cat >"$GROOT/test.sh" <<'GUEST'
. /gpio-sim-chip.sh
make_gpio_sim_chip 4 >/dev/null || exit 1
vivid_loop_feed /dev/video0 /dev/video1 /cam0.ppm &
feeder=$!
sleep 1
stripemuxd --supervise --trial-timeout 300 --state /state --board /boards/qemu \
  --status-every 30 >/tmp/stripemuxd.log 2>&1 &
supervisor=$!
until grep -q '^pairing code: ' /tmp/stripemuxd.log; do
  kill -0 "$supervisor" 2>/dev/null || { cat /tmp/stripemuxd.log; exit 1; }
  sleep 0.2
done
grep '^pairing code: ' /tmp/stripemuxd.log | sed 's/^/SMX-/'
echo "SMX-READY"
nc -l -p 7000 </dev/null >/dev/null
kill -TERM "$supervisor"
wait "$supervisor"
status=$?
kill "$feeder"
cat /tmp/stripemuxd.log
echo "active -> $(readlink /state/active)"
cat /state/boot.json
exit "$status"
GUEST
}

case_run() {
  local port stop_port guest status=0
  start_qemu_board || return 1
  local code device
  code=$(tr -d '\r' <"$WORK/console.log" | sed -n 's/^SMX-pairing code: \([0-9]*\) .*/\1/p' |
    sed -n 1p)
  device=127.0.0.1:$port
  export XDG_CONFIG_HOME=$WORK/host
  if ! "$STRIPEMUX" pair --device "$device" --code "$code" >"$WORK/pair.out" 2>&1; then
    kernel_log "pairing with code '$code' failed: $(cat "$WORK/pair.out")"
    status=1
  fi
  local flash_start=$SECONDS
  if [ "$status" -eq 0 ] &&
    ! "$STRIPEMUX" flash --device "$device" --wait 600 "$WORK/fw.smxb" >"$WORK/flash.out" \
      2>"$WORK/flash.err"; then
    kernel_log "flash failed: $(cat "$WORK/flash.err")"
    status=1
  fi
  kernel_log "bundle of $(stat -c %s "$WORK/fw.smxb") bytes flashed in $((SECONDS - flash_start)) s:" \
    "$(cat "$WORK/flash.out" 2>/dev/null)"
  if [ "$status" -eq 0 ] && [ "$(cat "$WORK/flash.out")" != "installed 0.2.0; running 0.2.0 in slot a" ]; then
    kernel_log "flash did not end with 0.2.0 running in slot a"
    status=1
  fi
  stop_qemu_board || status=1
  [ "$status" -eq 0 ] || return 1
  # The guest's own record: the supervisor ran the new slot and it marked itself good.
  grep -q '^active -> slots/a' "$WORK/console.log.txt" || {
    kernel_log "the guest's active link is not slots/a"
    return 1
  }
  grep -q 'slot a: self-test passed, marked good' "$WORK/console.log.txt" || {
    kernel_log "the new firmware did not mark itself good in the guest"
    return 1
  }
  kernel_log "0.2.0 installed in slot a, self-tested and marked good in the guest"
}
