# The whole firmware in the guest on the qemu board: stripemuxd captures a rendered scene through
# vivid's real V4L2 capture path (fed by vivid's video loop), triggers gpio-sim lines, decodes,
# and streams over virtio-net; the host's stripemux receives through qemu's port forward. Every
# depth image received must equal, bit for bit, `stripemux decode` of the same rendered image.
# shellcheck source=tests/kernel/firmware_board.sh
. "$KERNEL_DIR/firmware_board.sh"

case_stage() {
  [ -n "$HOST_BUILD" ] || kernel_die "the firmware test needs --host-build (stripemux, png_to_ppm)"
  STRIPEMUX=$HOST_BUILD/tools/host/stripemux
  [ -x "$STRIPEMUX" ] || kernel_skip "no host stripemux in $HOST_BUILD (build the host preset first)"
  local rig=$SOURCE_DIR/boards/sim/rig_2proj_1cam.json
  rm -rf "$WORK/expected" "$WORK/stream"
  stage_qemu_board "$rig"
  "$STRIPEMUX" decode --rig "$rig" --image cam0="$WORK/frames/cam0.png" --out "$WORK/expected" \
    >/dev/null
  cat >"$GROOT/test.sh" <<'GUEST'
. /gpio-sim-chip.sh
make_gpio_sim_chip 4 >/dev/null || exit 1
vivid_loop_feed /dev/video0 /dev/video1 /cam0.ppm &
feeder=$!
sleep 1
stripemuxd --board /boards/qemu --status-every 10 >/tmp/stripemuxd.log 2>&1 &
daemon=$!
until grep -q '^listening on' /tmp/stripemuxd.log; do
  kill -0 "$daemon" 2>/dev/null || exit 1
  sleep 0.2
done
echo "SMX-READY"
# The host connects here when it has what it wants; then the firmware stops as it would on a
# board (SIGTERM) and prints its counters.
nc -l -p 7000 </dev/null >/dev/null
kill -TERM "$daemon"
wait "$daemon"
status=$?
kill "$feeder"
cat /tmp/stripemuxd.log
exit "$status"
GUEST
}

case_run() {
  local port stop_port guest frames=3
  start_qemu_board || return 1
  local stream_start=$SECONDS status=0
  "$STRIPEMUX" stream --device "127.0.0.1:$port" --out "$WORK/stream" --frames "$frames" \
    --timeout 600 --no-ply || status=$?
  kernel_log "streamed $frames frames in $((SECONDS - stream_start)) s (stripemux exit $status)"
  # Stop the firmware; its verdict (SIGTERM must exit 0) is the guest's.
  stop_qemu_board || status=1
  [ "$status" -eq 0 ] || return 1

  local received=0 depth
  for depth in "$WORK"/stream/cam0_*.depth.png; do
    [ -f "$depth" ] || continue
    received=$((received + 1))
    if ! cmp -s "$depth" "$WORK/expected/cam0.depth.png"; then
      kernel_log "$(basename "$depth") differs from stripemux decode of the same image"
      status=1
    fi
  done
  if [ "$received" -lt "$frames" ]; then
    kernel_log "received $received depth images, wanted $frames"
    status=1
  fi
  [ "$status" -ne 0 ] || kernel_log "$received depth images received, each identical to stripemux decode"
  return "$status"
}
