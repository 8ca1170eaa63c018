# The V4L2 camera backend on vivid: formats, 100 frames at the asked rate, a dequeue timeout,
# and recovery from an unplug (vivid's Disconnect control) with the driver unloaded and loaded.
case_stage() {
  stage_modules "vivid=n_devs=1 node_types=0x1"
  stage_binary "$BUILD/tests/kernel/kernel_guest_test"
  echo "kernel_guest_test --gtest_filter='V4l2Vivid.*'" >"$GROOT/test.sh"
}
