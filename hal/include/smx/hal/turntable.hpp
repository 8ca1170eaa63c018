#pragma once

#include <cstdint>

#include "smx/hal/error.hpp"

// A stepper turntable (docs/hal.md, "Turntable"): the board turns it by whole steps and knows its
// position by counting them (there is no encoder), so the position is relative to where the
// table stood at start-up. A move blocks for the whole motion and the settle time after it.
namespace smx::hal {

class Turntable {
 public:
  virtual ~Turntable() = default;
  Turntable(const Turntable&) = delete;
  Turntable& operator=(const Turntable&) = delete;

  // Steps of one full turn of the table (motor steps times microsteps times gearing).
  [[nodiscard]] virtual std::int32_t stepsPerTurn() const = 0;
  // Signed steps since start-up; positive turns right-handed about the rig's turntable axis.
  [[nodiscard]] virtual std::int64_t position() const = 0;
  // Drives `steps` (negative: the other way) at the board's speed, then waits its settle time.
  // On a failure the position counts the steps that were driven.
  [[nodiscard]] virtual HalResult<void> move(std::int32_t steps) = 0;

 protected:
  Turntable() = default;
};

}  // namespace smx::hal
