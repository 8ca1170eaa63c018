# The qemu board as the firmware cases stage it (sourced by cases/firmware.sh and
# cases/update.sh): vivid fed with a rendered frame through its video loop, gpio-sim trigger
# lines, virtio-net, and the board's files; the guest's daemon as /bin/stripemuxd.
#   stage_qemu_board RIG   (renders into $WORK/frames; needs $STRIPEMUX and $HOST_BUILD)
stage_qemu_board() {
  local rig=$1
  rm -rf "$WORK/frames"
  "$STRIPEMUX" sim --rig "$rig" --scene bunny --out "$WORK/frames" --no-truth >/dev/null
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
  stage_file "$rig" "/boards/sim/$(basename "$rig")"
  stage_file "$KERNEL_DIR/guest/gpio-sim-chip.sh" /gpio-sim-chip.sh
  build_extra_modules || kernel_die "gpio-sim cannot be built for $KARCH"
  stage_modules gpio-sim
}

# Boots the guest with the device's port (5555) and a stop port (7000) forwarded to free host
# ports ($port, $stop_port); the guest's pid is $guest. Waits for SMX-READY on its console.
start_qemu_board() {
  port=$(free_port)
  stop_port=$(free_port)
  while [ "$stop_port" = "$port" ]; do stop_port=$(free_port); done
  # A console left by an earlier run must not be taken for this guest's.
  rm -f "$WORK/console.log" "$WORK/console.log.txt" "$WORK/qemu.pid"
  KERNEL_GUEST_CPUS=2 run_guest "$WORK/initramfs.gz" "$WORK/console.log" 900 \
    -pidfile "$WORK/qemu.pid" \
    -netdev "user,id=n0,hostfwd=tcp:127.0.0.1:$port-:5555,hostfwd=tcp:127.0.0.1:$stop_port-:7000" \
    -device virtio-net-pci,netdev=n0 &
  guest=$!
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
}

# Asks the guest to stop its firmware (a connection to the stop port), then waits for its
# verdict; 1 if the guest failed.
stop_qemu_board() {
  if ! (exec 3<>"/dev/tcp/127.0.0.1/$stop_port") 2>/dev/null; then
    kernel_log "cannot reach the guest to stop it"
    stop_guest_now
  fi
  wait "$guest"
}

# When the host side has failed there is nothing to wait for.
stop_guest_now() {
  [ -f "$WORK/qemu.pid" ] && kill "$(cat "$WORK/qemu.pid")" 2>/dev/null
  return 0
}
