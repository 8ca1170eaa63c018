#pragma once

#include <cstddef>
#include <cstdint>
#include <expected>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/hal/camera.hpp"
#include "smx/linux/v4l2_controls.hpp"
#include "smx/linux/v4l2_io.hpp"

// hal::Camera on a V4L2 single-planar capture device with mmap streaming (UVC webcams, CSI
// bridges that expose /dev/videoN, vivid). Frames are RGB24 as the driver fills them (no copy),
// or BGR24/YUYV converted into RGB buffers allocated at start(). acquire() and release() never
// allocate.
//
// States: kUnconfigured --configure--> kStopped --start--> kStreaming --stop--> kStopped.
// When the device goes away (ENODEV, EIO, POLLERR/POLLHUP) the call that noticed it returns
// kDisconnected and the camera is "lost": every call but release(), stop() and reopen() fails
// with kDisconnected, state() says kStopped (or kUnconfigured). Borrowed frames stay readable
// until reopen() or stop(): the mappings outlive the descriptor. reopen() opens the same path
// and restores the format and, if it was streaming, streaming.
namespace smx::lnx {

class V4l2Camera final : public hal::Camera {
 public:
  static constexpr int kMinBuffers = 2;
  static constexpr int kMaxBuffers = 32;

  // Opens the device and checks it can capture and stream (init time; the error names the
  // device). `io` must outlive the camera.
  [[nodiscard]] static std::expected<std::unique_ptr<V4l2Camera>, std::string> create(
      std::string devicePath, std::string cameraId, int buffers, V4l2Io& io);
  ~V4l2Camera() override;
  V4l2Camera(const V4l2Camera&) = delete;
  V4l2Camera& operator=(const V4l2Camera&) = delete;

  [[nodiscard]] hal::HalResult<hal::CameraFormat> configure(
      const hal::CameraFormat& wanted) override;
  [[nodiscard]] hal::HalResult<void> start() override;
  [[nodiscard]] hal::HalResult<void> stop() override;
  [[nodiscard]] hal::HalResult<hal::CameraFrame> acquire(std::int64_t timeoutNs) override;
  [[nodiscard]] hal::HalResult<void> release(const hal::CameraFrame& frame) override;
  [[nodiscard]] hal::HalResult<void> setControls(const hal::CameraControls& controls) override;
  [[nodiscard]] hal::CameraControlSupport controlSupport() const override {
    return controls_.support();
  }
  [[nodiscard]] hal::CameraState state() const override { return state_; }
  [[nodiscard]] std::string_view id() const override { return id_; }

  // After kDisconnected: opens the device again and restores format and streaming. Fails with
  // kDisconnected while the device is still absent. A no-op while the device is present.
  [[nodiscard]] hal::HalResult<void> reopen();
  [[nodiscard]] hal::HalResult<void> recover() override { return reopen(); }
  [[nodiscard]] bool lost() const { return !fd_.valid(); }

  [[nodiscard]] std::string_view devicePath() const { return path_; }
  [[nodiscard]] int bufferCount() const { return static_cast<int>(buffers_.size()); }
  // Counters (per frame: counted, never logged).
  [[nodiscard]] std::uint64_t corruptFrames() const { return corruptFrames_; }
  // Frames exposed before acquire() was called, skipped (see hal::Camera::acquire).
  [[nodiscard]] std::uint64_t staleFrames() const { return staleFrames_; }
  [[nodiscard]] std::uint64_t disconnects() const { return disconnects_; }

 private:
  struct Buffer {
    std::byte* mapped = nullptr;
    std::size_t length = 0;
    std::vector<algo::Rgb8> rgb;  // converted frame (not RGB24)
    bool borrowed = false;
    std::uint64_t sequence = 0;  // of the frame borrowed from it
  };

  V4l2Camera(std::string path, std::string id, int buffers, V4l2Fd fd, V4l2Io& io)
      : path_(std::move(path)),
        id_(std::move(id)),
        wantedBuffers_(buffers),
        fd_(std::move(fd)),
        io_(io),
        controls_(V4l2Controls::query(io, fd_.get())) {}

  [[nodiscard]] hal::HalResult<hal::CameraFormat> negotiate(const hal::CameraFormat& wanted);
  [[nodiscard]] hal::HalResult<void> startStreaming();
  [[nodiscard]] hal::HalResult<void> queue(int index);
  [[nodiscard]] hal::HalResult<hal::CameraFrame> deliver(int index, std::uint32_t bytesUsed,
                                                         std::int64_t timestampNs,
                                                         std::uint32_t sequence);
  // Unmaps and frees the buffers and, while the device is present, REQBUFS 0.
  void freeBuffers();
  // Closes the descriptor after the device went away; the call that noticed returns this.
  [[nodiscard]] std::unexpected<hal::HalError> markLost(int err);

  std::string path_;
  std::string id_;
  int wantedBuffers_;
  V4l2Fd fd_;  // invalid while the device is lost
  V4l2Io& io_;
  V4l2Controls controls_;
  hal::CameraControls wantedControls_;  // as set (reopen() sets them again)
  hal::CameraState state_ = hal::CameraState::kUnconfigured;
  bool resumeStreaming_ = false;  // streaming when the device was lost
  hal::CameraFormat wanted_;      // as asked for (reopen() asks again)
  hal::CameraFormat format_;      // as granted
  std::uint32_t bytesPerLine_ = 0;
  std::size_t frameBytes_ = 0;  // a frame's bytes in a driver buffer, stride included
  std::vector<Buffer> buffers_;
  int borrowedCount_ = 0;
  std::uint64_t sequence_ = 0;  // the driver's 32-bit sequence, unwrapped
  std::uint32_t lastSequence_ = 0;
  bool firstFrame_ = true;
  std::uint64_t corruptFrames_ = 0;
  std::uint64_t staleFrames_ = 0;
  std::uint64_t disconnects_ = 0;
};

}  // namespace smx::lnx
