#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "smx/algo/rig.hpp"
#include "smx/config/board_json.hpp"
#include "smx/device/device.hpp"
#include "smx/hal/board_hal.hpp"
#include "smx/sim/sim_board.hpp"

// Test support, host only: the firmware's Device on the simulated board, in this process, on a
// free loopback port, its loops in threads as stripemuxd runs them.
namespace smx::test {

// boards/<folder> of the source tree on a free loopback port. Throws with the loader's reason.
[[nodiscard]] config::Board sourceBoard(std::string_view folder);

// `board` rendering `scene` live (a named scene or a scene.json) and announcing `rig`: its cameras
// cut to the rig's, at 1000 fps so that the loop, not the sensor, sets the pace.
[[nodiscard]] config::Board renderingScene(config::Board board, const std::string& scene,
                                           const algo::Rig& rig);

// Which loops run beside the network loop.
enum class SimLoops : std::uint8_t {
  kNetwork,  // none: the test calls the device itself (or startCapture() later)
  kServe,    // raw captures and turns only, no range captures: camera frame k is raw capture k
  kCapture,  // Device::runCapture(): raw captures, turns and range captures, as stripemuxd
};

struct SimDeviceOptions {
  SimLoops loops = SimLoops::kNetwork;
  // The rig the simulator renders with, when it is not the one the board announces (a rig that
  // drifted since its calibration).
  std::optional<algo::Rig> renderedRig{};
  device::DeviceOptions device{};
};

class SimDevice {
 public:
  // Creates the HAL and the Device and starts the loops. Throws std::runtime_error naming what
  // failed.
  explicit SimDevice(config::Board board, const SimDeviceOptions& options = {});
  // Stops the loops and joins them, the capture loop first.
  ~SimDevice();
  SimDevice(const SimDevice&) = delete;
  SimDevice& operator=(const SimDevice&) = delete;
  SimDevice(SimDevice&&) = delete;
  SimDevice& operator=(SimDevice&&) = delete;

  // Starts Device::runCapture() (with SimLoops::kNetwork; no-op when a loop already runs).
  void startCapture();
  // Serves the next raw capture a host asks for, on this thread; false when none came in 10 s.
  [[nodiscard]] bool serveOne();

  [[nodiscard]] std::uint16_t port() const;
  [[nodiscard]] std::string address() const;  // "127.0.0.1:<port>"
  [[nodiscard]] const config::Board& board() const { return board_; }
  [[nodiscard]] device::Device& device() const { return *device_; }
  [[nodiscard]] hal::Hal hal() const { return boardHal_->hal(); }
  [[nodiscard]] sim::SimBoardControl& control() const { return *control_; }

 private:
  config::Board board_;
  std::unique_ptr<hal::BoardHal> boardHal_;
  sim::SimBoardControl* control_ = nullptr;
  std::unique_ptr<device::Device> device_;
  std::atomic<bool> stopNetwork_ = false;
  std::atomic<bool> stopCapture_ = false;
  std::jthread network_;
  std::jthread capture_;
};

}  // namespace smx::test
