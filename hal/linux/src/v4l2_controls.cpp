#include "smx/linux/v4l2_controls.hpp"

#include <linux/videodev2.h>

#include <cerrno>
#include <cmath>

namespace smx::lnx {

using hal::HalErrc;
using hal::halFail;

namespace {
constexpr int kExposureUnitUs = 100;  // V4L2_CID_EXPOSURE_ABSOLUTE counts 100 µs
}  // namespace

std::optional<V4l2Controls::Control> V4l2Controls::find(V4l2Io& io, int fd, std::uint32_t id) {
  v4l2_queryctrl query{};
  query.id = id;
  if (io.ioctl(fd, VIDIOC_QUERYCTRL, &query) < 0 ||
      (query.flags & (V4L2_CTRL_FLAG_DISABLED | V4L2_CTRL_FLAG_READ_ONLY)) != 0) {
    return std::nullopt;
  }
  return Control{.id = id,
                 .minimum = query.minimum,
                 .maximum = query.maximum,
                 .defaultValue = query.default_value};
}

V4l2Controls V4l2Controls::query(V4l2Io& io, int fd) {
  V4l2Controls controls;
  controls.exposure_ = find(io, fd, V4L2_CID_EXPOSURE_ABSOLUTE);
  controls.exposureAuto_ = find(io, fd, V4L2_CID_EXPOSURE_AUTO);
  controls.gain_ = find(io, fd, V4L2_CID_ANALOGUE_GAIN);
  if (!controls.gain_) {
    controls.gain_ = find(io, fd, V4L2_CID_GAIN);
  }
  // Unity gain must be a value the control can take.
  if (controls.gain_ && controls.gain_->defaultValue <= 0) {
    controls.gain_.reset();
  }
  return controls;
}

hal::HalResult<void> V4l2Controls::apply(V4l2Io& io, int fd,
                                         const hal::CameraControls& controls) const {
  if ((controls.exposureUs && !exposure_) || (controls.gain && !gain_)) {
    return halFail(HalErrc::kNotSupported, controls.exposureUs && !exposure_
                                               ? "the camera has no exposure control"
                                               : "the camera has no gain control");
  }
  const auto set = [&](const Control& control, std::int64_t value) -> hal::HalResult<void> {
    if (value < control.minimum || value > control.maximum) {
      return halFail(HalErrc::kInvalidArgument, "a value outside the camera's control range");
    }
    v4l2_control c{.id = control.id, .value = static_cast<std::int32_t>(value)};
    if (const int r = io.ioctl(fd, VIDIOC_S_CTRL, &c); r < 0) {
      return halFail(r == -ENODEV ? HalErrc::kDisconnected : HalErrc::kIo, "VIDIOC_S_CTRL failed",
                     -r);
    }
    return {};
  };
  if (exposureAuto_) {
    const std::int64_t mode =
        controls.exposureUs ? V4L2_EXPOSURE_MANUAL : exposureAuto_->defaultValue;
    if (auto ok = set(*exposureAuto_, mode); !ok) {
      return ok;
    }
  }
  if (exposure_) {
    const std::int64_t value = controls.exposureUs
                                   ? std::llround(*controls.exposureUs / double{kExposureUnitUs})
                                   : exposure_->defaultValue;
    if (auto ok = set(*exposure_, value); !ok) {
      return ok;
    }
  }
  if (gain_) {
    const std::int64_t value =
        controls.gain ? std::llround(*controls.gain * gain_->defaultValue) : gain_->defaultValue;
    if (auto ok = set(*gain_, value); !ok) {
      return ok;
    }
  }
  return {};
}

}  // namespace smx::lnx
