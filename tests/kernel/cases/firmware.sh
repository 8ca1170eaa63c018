# The whole firmware in the guest on the qemu board: stripemuxd captures a rendered scene through
# vivid's real V4L2 capture path (fed by vivid's video loop), triggers gpio-sim lines, decodes,
# and streams over virtio-net; the host's stripemux receives through qemu's port forward. Every
# depth image received must equal, bit for bit, `stripemux decode` of the same rendered image.
case_stage() {
  [ -n "$HOST_BUILD" ] || kernel_die "the firmware test needs --host-build (stripemux, png_to_ppm)"
  STRIPEMUX=$HOST_BUILD/tools/host/stripemux
  [ -x "$STRIPEMUX" ] || kernel_skip "no host stripemux in $HOST_BUILD (build the host preset first)"
  local rig=$SOURCE_DIR/boards/sim/rig_2proj_1cam.json
  rm -rf "$WORK/frames" "$WORK/expected" "$WORK/stream"
  "$STRIPEMUX" sim --rig "$rig" --scene bunny --out "$WORK/frames" --no-truth >/dev/null
  "$STRIPEMUX" decode --rig "$rig" --image cam0="$WORK/frames/cam0.png" --out "$WORK/expected" \
    >/dev/null
  "$HOST_BUILD/tests/kernel/png_to_ppm" "$WORK/frames/cam0.png" "$WORK/cam0.ppm"

  local daemon=$BUILD/firmware/stripemuxd
  [ "$KARCH" = aarch64 ] || daemon=$BUILD/firmware/stripemuxd-linux
  # vivid with one HDMI input and one HDMI output, capture and output nodes (video0, video1).
  stage_modules "vivid=n_devs=1 node_types=0x101 num_inputs=1 input_types=0x3 num_outputs=1 output_types=0x1" \
    virtio_pci virtio_net
  stage_binary "$daemon" /bin/stripemuxd
  stage_binary "$BUILD/tests/kernel/vivid_loop_feed"
  stage_file "$WORK/cam0.ppm" /cam0.ppm
  stage_file "$SOURCE_DIR/boards/qemu" /boards/qemu
  stage_file "$rig" /boards/sim/rig_2proj_1cam.json
  stage_file "$KERNEL_DIR/guest/gpio-sim-chip.sh" /gpio-sim-chip.sh
  build_extra_modules || kernel_die "gpio-sim cannot be built for $KARCH"
  stage_modules gpio-sim
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
  local port stop_port frames=3
  port=$(free_port)
  stop_port=$(free_port)
  while [ "$stop_port" = "$port" ]; do stop_port=$(free_port); done
  # A console left by an earlier run must not be taken for this guest's.
  rm -f "$WORK/console.log" "$WORK/console.log.txt" "$WORK/qemu.pid"
  KERNEL_GUEST_CPUS=2 run_guest "$WORK/initramfs.gz" "$WORK/console.log" 900 \
    -pidfile "$WORK/qemu.pid" \
    -netdev "user,id=n0,hostfwd=tcp:127.0.0.1:$port-:5555,hostfwd=tcp:127.0.0.1:$stop_port-:7000" \
    -device virtio-net-pci,netdev=n0 &
  local guest=$!
  local waited=0
  until grep -q '^SMX-READY' "$WORK/console.log" 2>/dev/null; do
    if ! kill -0 "$guest" 2>/dev/null || [ $waited -ge 300 ]; then
      kernel_log "the guest's firmware never started"
      stop_guest_now
      wait "$guest" || true
      return 1
    fi
    sleep 1
    waited=$((waited + 1))
  done
  local stream_start=$SECONDS status=0
  "$STRIPEMUX" stream --device "127.0.0.1:$port" --out "$WORK/stream" --frames "$frames" \
    --timeout 600 --no-ply || status=$?
  kernel_log "streamed $frames frames in $((SECONDS - stream_start)) s (stripemux exit $status)"
  # Ask the guest to stop its firmware, then wait for its verdict (SIGTERM must exit 0).
  if ! (exec 3<>"/dev/tcp/127.0.0.1/$stop_port") 2>/dev/null; then
    kernel_log "cannot reach the guest to stop it"
    stop_guest_now
  fi
  wait "$guest" || status=1
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

# When the host side has failed there is nothing to wait for.
stop_guest_now() {
  [ -f "$WORK/qemu.pid" ] && kill "$(cat "$WORK/qemu.pid")" 2>/dev/null
  return 0
}
