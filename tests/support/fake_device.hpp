#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "smx/hal/unique_fd.hpp"

// A device that says whatever a test tells it to: capabilities with any board name and rig, range
// frames, statistics. It stands in for a hostile or broken device (devices are unauthenticated,
// discovery can be spoofed) in tests of the host tool. Serves one connection on 127.0.0.1.
namespace smx::test {

struct FakeDeviceScript {
  std::string board = "fake";
  std::string firmwareVersion = "0.0.0";
  std::string rigJson;  // sent as the device's rig
  int width = 0;        // of the range frames and in the capabilities
  int height = 0;
  int framesPerStart = 2;  // range frames of camera 0 sent after start-stream
};

class FakeDevice {
 public:
  explicit FakeDevice(FakeDeviceScript script);
  FakeDevice(const FakeDevice&) = delete;
  FakeDevice& operator=(const FakeDevice&) = delete;
  ~FakeDevice();

  // "127.0.0.1:PORT", for --device.
  [[nodiscard]] std::string address() const;

 private:
  void serve();

  FakeDeviceScript script_;
  hal::UniqueFd listener_;
  std::uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace smx::test
