#pragma once

#include <cstdint>

// The board's monotonic clock: frame timestamps, rates and timeouts.
namespace smx::hal {

class Clock {
 public:
  virtual ~Clock() = default;
  Clock(const Clock&) = delete;
  Clock& operator=(const Clock&) = delete;

  [[nodiscard]] virtual std::int64_t nowNs() const = 0;
  virtual void sleepUntilNs(std::int64_t deadlineNs) = 0;

 protected:
  Clock() = default;
};

}  // namespace smx::hal
