#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "sim_trigger.hpp"
#include "sim_turntable.hpp"
#include "smx/hal/camera.hpp"
#include "smx/hal/clock.hpp"
#include "smx/sim/png_io.hpp"
#include "smx/sim/renderer.hpp"

// A camera of the simulated board with V4L2's buffer rules (docs/hal.md). Its frames come from
// the renderer, with the projectors whose trigger lines are active lit, or from a replayed list
// of images. It keeps the configured frame rate like a real sensor: acquire() waits for the next
// frame time, and a consumer that falls behind loses the frames it missed (the sequence jumps).
// Replay is allocation-free per frame; rendering allocates inside the renderer (the simulated
// world, not the firmware), so allocation tests replay.
namespace smx::sim {

// The exposure a rendered frame has at exposure scale 1: the scene's light levels are what the
// camera sees in this time at unity gain.
inline constexpr int kSimNominalExposureUs = 10'000;
inline constexpr int kSimMaxExposureUs = 1'000'000;
inline constexpr double kSimMaxGain = 16.0;

struct SimCameraSource {
  Renderer* renderer = nullptr;  // render live, or
  int rigCamera = 0;
  std::uint64_t seed = 1;
  const std::vector<RgbImage>* replay = nullptr;  // replay these in a loop
  const SimTurntable* turntable = nullptr;        // the angle its objects are rendered at
};

class SimCamera final : public hal::Camera {
 public:
  SimCamera(std::string id, SimCameraSource source, const SimTrigger& trigger, hal::Clock& clock,
            hal::CameraFormat nativeFormat, int buffers);

  [[nodiscard]] hal::HalResult<hal::CameraFormat> configure(
      const hal::CameraFormat& wanted) override;
  [[nodiscard]] hal::HalResult<void> start() override;
  [[nodiscard]] hal::HalResult<void> stop() override;
  [[nodiscard]] hal::HalResult<hal::CameraFrame> acquire(std::int64_t timeoutNs) override;
  [[nodiscard]] hal::HalResult<void> release(const hal::CameraFrame& frame) override;
  [[nodiscard]] hal::HalResult<void> recover() override;
  [[nodiscard]] hal::HalResult<void> setControls(const hal::CameraControls& controls) override;
  [[nodiscard]] hal::CameraControlSupport controlSupport() const override;
  [[nodiscard]] hal::CameraState state() const override { return state_; }
  [[nodiscard]] std::string_view id() const override { return id_; }

  // Faults (test control, any thread).
  void injectTimeouts(int count) { pendingTimeouts_ += count; }
  void setConnected(bool connected) { connected_ = connected; }
  void dropFrames(int count) { pendingDrops_ += count; }
  [[nodiscard]] std::uint32_t lastExposureMask() const { return lastExposureMask_; }
  [[nodiscard]] std::uint64_t delivered() const { return delivered_; }

 private:
  [[nodiscard]] hal::HalResult<void> produce(int buffer);

  std::string id_;
  SimCameraSource source_;
  const SimTrigger& trigger_;
  hal::Clock& clock_;
  hal::CameraFormat native_;
  hal::CameraFormat format_;
  int bufferCount_;
  hal::CameraState state_ = hal::CameraState::kUnconfigured;
  std::vector<std::vector<algo::Rgb8>> buffers_;
  std::vector<bool> borrowed_;
  std::int64_t streamStartNs_ = 0;
  std::uint64_t sequence_ = 0;
  std::atomic<int> pendingTimeouts_ = 0;
  std::atomic<int> pendingDrops_ = 0;
  std::atomic<bool> connected_ = true;
  std::atomic<std::uint32_t> lastExposureMask_ = 0;
  std::atomic<std::uint64_t> delivered_ = 0;
  std::atomic<int> exposureUs_ = kSimNominalExposureUs;
  std::atomic<double> gain_ = 1.0;
};

}  // namespace smx::sim
