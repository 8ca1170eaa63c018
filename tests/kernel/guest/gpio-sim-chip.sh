# Sourced by guest test scripts: make_gpio_sim_chip LINES creates a live gpio-sim chip through
# configfs, with lines 0 and 1 named after the projectors they trigger on the qemu board, and
# prints the sysfs folder of its lines (sim_gpio<N>/value).
make_gpio_sim_chip() {
  config=/sys/kernel/config/gpio-sim/chip0
  mkdir "$config" "$config/bank0" || return 1
  echo "$1" >"$config/bank0/num_lines"
  for line in 0 1; do
    mkdir "$config/bank0/line$line"
    echo "proj$line" >"$config/bank0/line$line/name"
  done
  echo 1 >"$config/live" || return 1
  echo "/sys/devices/platform/$(cat "$config/dev_name")/$(cat "$config/bank0/chip_name")"
}
