#pragma once

#include "smx/hal/clock.hpp"

// The clock of every Linux board and of the simulated one: CLOCK_MONOTONIC, the clock V4L2
// timestamps its buffers with.
namespace smx::hal {

class SteadyClock final : public Clock {
 public:
  SteadyClock() = default;
  [[nodiscard]] std::int64_t nowNs() const override;
  void sleepUntilNs(std::int64_t deadlineNs) override;
};

}  // namespace smx::hal
