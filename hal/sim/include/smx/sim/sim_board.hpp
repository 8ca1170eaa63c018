#pragma once

#include <cstdint>
#include <vector>

#include "smx/hal/board_hal.hpp"

// The simulated board's test-only control API (like Zephyr's gpio_emul): faults to inject into
// its cameras and what its outputs did. The firmware never sees it; tests reach it through the
// BoardHal they handed to the firmware.
namespace smx::sim {

struct TriggerEdge {
  std::int64_t timeNs = 0;
  std::uint32_t activeMask = 0;  // the lines' state after the edge
};

class SimBoardControl {
 public:
  virtual ~SimBoardControl() = default;

  // The camera's next `count` acquires time out.
  virtual void injectTimeouts(int camera, int count) = 0;
  // The camera vanishes (acquire fails with kDisconnected) until reconnected.
  virtual void disconnect(int camera) = 0;
  virtual void reconnect(int camera) = 0;
  // The camera loses its next `count` frames (the sequence number jumps).
  virtual void dropFrames(int camera, int count) = 0;

  // Every change of the trigger lines so far, oldest first (the last 4096).
  [[nodiscard]] virtual std::vector<TriggerEdge> triggerEdges() const = 0;
  // The trigger lines' state during the camera's latest exposure.
  [[nodiscard]] virtual std::uint32_t lastExposureMask(int camera) const = 0;
  [[nodiscard]] virtual std::uint64_t framesDelivered(int camera) const = 0;

 protected:
  SimBoardControl() = default;
};

// The control of a board made by the sim backend's createBoardHal(), else nullptr.
[[nodiscard]] SimBoardControl* simBoardControl(hal::BoardHal& board);

}  // namespace smx::sim
