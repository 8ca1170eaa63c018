#pragma once

#include <cstdint>
#include <optional>

#include "smx/hal/camera.hpp"
#include "smx/linux/v4l2_io.hpp"

// The exposure and gain controls of a V4L2 camera (docs/hal.md, "Camera controls"): found with
// VIDIOC_QUERYCTRL when the device is opened, set with VIDIOC_S_CTRL. Exposure is
// V4L2_CID_EXPOSURE_ABSOLUTE (100 µs units) with V4L2_CID_EXPOSURE_AUTO set to manual; gain is
// V4L2_CID_ANALOGUE_GAIN, else V4L2_CID_GAIN, whose units are the sensor's: its default is taken
// as unity gain, so gain g is g × the default.
namespace smx::lnx {

class V4l2Controls {
 public:
  // Queries the controls the device has (no control: that setting is unsupported).
  static V4l2Controls query(V4l2Io& io, int fd);

  [[nodiscard]] hal::CameraControlSupport support() const {
    return {.exposure = exposure_.has_value(), .gain = gain_.has_value()};
  }
  // Sets what `controls` holds and puts the others back to the driver's defaults.
  [[nodiscard]] hal::HalResult<void> apply(V4l2Io& io, int fd,
                                           const hal::CameraControls& controls) const;

 private:
  struct Control {
    std::uint32_t id = 0;
    std::int32_t minimum = 0;
    std::int32_t maximum = 0;
    std::int32_t defaultValue = 0;
  };
  static std::optional<Control> find(V4l2Io& io, int fd, std::uint32_t id);

  std::optional<Control> exposure_;
  std::optional<Control> exposureAuto_;
  std::optional<Control> gain_;
};

}  // namespace smx::lnx
