# The qemu board's trigger lines on gpio-sim around captures of its vivid camera, read back from
# gpio-sim's sysfs values.
case_stage() {
  build_extra_modules
  stage_modules "vivid=n_devs=1 node_types=0x1" gpio-sim
  stage_binary "$BUILD/tests/kernel/kernel_guest_test"
  stage_file "$SOURCE_DIR/boards/qemu" /boards/qemu
  stage_file "$SOURCE_DIR/boards/sim/rig_2proj_1cam.json" /boards/sim/rig_2proj_1cam.json
  stage_file "$KERNEL_DIR/guest/gpio-sim-chip.sh" /gpio-sim-chip.sh
  cat >"$GROOT/test.sh" <<'GUEST'
. /gpio-sim-chip.sh
lines=$(make_gpio_sim_chip 4) || exit 1
SMX_BOARD=/boards/qemu SMX_GPIO_SIM=$lines kernel_guest_test --gtest_filter='GpioSimTrigger.*'
GUEST
}
