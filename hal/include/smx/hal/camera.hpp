#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "smx/algo/image_view.hpp"
#include "smx/hal/error.hpp"

// A camera that streams into a fixed set of buffers, with V4L2's rules (docs/hal.md):
// configure() while stopped, start(), then acquire() borrows the oldest filled buffer and
// release() gives it back to be filled again. While every buffer is borrowed the camera has
// nowhere to write and acquire() fails with kBusy; a frame must be released before it is reused
// and only once. Frames are handed out as 8-bit RGB whatever the wire format: a backend converts
// (YUYV, BGR24) into buffers it owns.
namespace smx::hal {

enum class PixelFormat : std::uint8_t { kRgb24, kBgr24, kYuyv };

[[nodiscard]] std::string_view toString(PixelFormat format);

struct CameraFormat {
  int width = 0;
  int height = 0;
  PixelFormat pixelFormat = PixelFormat::kRgb24;
  int fps = 30;
};

struct CameraFrame {
  int bufferIndex = -1;          // which buffer is borrowed; pass the frame back to release()
  std::uint64_t sequence = 0;    // counts frames the camera produced, dropped ones included
  std::int64_t timestampNs = 0;  // when the frame was captured, the board clock (Clock::nowNs)
  algo::ConstRgbView image;
};

// Settings of the sensor a structured-light scanner must own: automatic exposure would follow
// the projectors' patterns. Absent: the camera's own (as the driver starts it).
struct CameraControls {
  std::optional<int> exposureUs;  // exposure time, microseconds
  std::optional<double> gain;     // sensor (analogue) gain, 1 = unity
};

// Which controls a camera has: what setControls() accepts.
struct CameraControlSupport {
  bool exposure = false;
  bool gain = false;
};

enum class CameraState : std::uint8_t { kUnconfigured, kStopped, kStreaming };

class Camera {
 public:
  virtual ~Camera() = default;
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;

  // Negotiates the format; the device may adjust fps (never the size or pixel format: a different
  // size or format is kNotSupported). Returns what the device will deliver.
  [[nodiscard]] virtual HalResult<CameraFormat> configure(const CameraFormat& wanted) = 0;
  [[nodiscard]] virtual HalResult<void> start() = 0;
  // Returns every borrowed buffer; frames acquired before are invalid afterwards.
  [[nodiscard]] virtual HalResult<void> stop() = 0;
  // Waits at most timeoutNs for the next frame: one whose exposure began after the call, so that
  // it sees the projectors lit before the call. Frames the camera took earlier are dropped.
  [[nodiscard]] virtual HalResult<CameraFrame> acquire(std::int64_t timeoutNs) = 0;
  [[nodiscard]] virtual HalResult<void> release(const CameraFrame& frame) = 0;
  // After kDisconnected: tries to reopen the device and return to the state it was in
  // (configured, streaming). kDisconnected while it is still gone.
  [[nodiscard]] virtual HalResult<void> recover() {
    return halFail(HalErrc::kNotSupported, "this camera cannot recover");
  }

  // Sets the controls that are present (while configured, streaming or not); a control the
  // camera lacks or a value out of its range is kNotSupported / kInvalidArgument naming it.
  [[nodiscard]] virtual HalResult<void> setControls(const CameraControls& controls) {
    if (controls.exposureUs || controls.gain) {
      return halFail(HalErrc::kNotSupported, "this camera has no exposure or gain control");
    }
    return {};
  }
  [[nodiscard]] virtual CameraControlSupport controlSupport() const { return {}; }

  [[nodiscard]] virtual CameraState state() const = 0;
  [[nodiscard]] virtual std::string_view id() const = 0;  // the rig's camera id

 protected:
  Camera() = default;
};

}  // namespace smx::hal
