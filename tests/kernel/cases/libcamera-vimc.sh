# The libcamera backend on vimc (built out of tree), with Debian's libcamera and its vimc IPA.
case_stage() {
  build_extra_modules
  stage_modules vimc
  stage_binary "$BUILD/tests/kernel/kernel_guest_test"
  local ipa=/usr/lib/x86_64-linux-gnu/libcamera
  [ -f "$ipa/ipa_vimc.so" ] || kernel_die "no $ipa/ipa_vimc.so (libcamera-ipa)"
  stage_file "$ipa/ipa_vimc.so" "$ipa/ipa_vimc.so"
  stage_file "$ipa/ipa_vimc.so.sign" "$ipa/ipa_vimc.so.sign"
  stage_binary "$ipa/vimc_ipa_proxy" "$ipa/vimc_ipa_proxy"
  stage_file /usr/share/libcamera/ipa/vimc /usr/share/libcamera/ipa/vimc
  cat >"$GROOT/test.sh" <<'GUEST'
# No udevd in the guest: libcamera's udev enumerator skips devices udev has not initialised,
# so mark every media, video and subdevice node as initialised.
mkdir -p /run/udev/data
for dev in /sys/class/video4linux/*/dev /sys/bus/media/devices/*/dev; do
  echo "I:1" >"/run/udev/data/c$(cat "$dev")"
done
export LIBCAMERA_LOG_LEVELS='*:ERROR'
kernel_guest_test --gtest_filter='LibcameraVimc.*'
GUEST
}
