#include "smx/hal/steady_clock.hpp"

#include <cerrno>
#include <ctime>

namespace smx::hal {

namespace {
constexpr std::int64_t kNsPerS = 1'000'000'000;
}

std::int64_t SteadyClock::nowNs() const {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * kNsPerS + now.tv_nsec;
}

void SteadyClock::sleepUntilNs(std::int64_t deadlineNs) {
  const timespec deadline{.tv_sec = static_cast<time_t>(deadlineNs / kNsPerS),
                          .tv_nsec = static_cast<long>(deadlineNs % kNsPerS)};
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
  }
}

}  // namespace smx::hal
