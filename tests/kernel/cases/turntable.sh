# The turntable's STEP, DIR and ENABLE lines (GpiodTurntable) on gpio-sim lines 2, 3 and 4: every
# value set on a line is read back from the kernel's gpio_value tracepoint, so each STEP pulse
# is counted however short it is.
case_stage() {
  build_extra_modules
  stage_modules gpio-sim
  stage_binary "$BUILD/tests/kernel/kernel_guest_test"
  stage_file "$KERNEL_DIR/guest/gpio-sim-chip.sh" /gpio-sim-chip.sh
  cat >"$GROOT/test.sh" <<'GUEST'
. /gpio-sim-chip.sh
lines=$(make_gpio_sim_chip 5) || exit 1
mkdir -p /sys/kernel/tracing
mount -t tracefs tracefs /sys/kernel/tracing || exit 1
SMX_GPIO_SIM=$lines SMX_TRACEFS=/sys/kernel/tracing \
  kernel_guest_test --gtest_filter='GpioSimTurntable.*'
GUEST
}
