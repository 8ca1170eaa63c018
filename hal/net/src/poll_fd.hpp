#pragma once

#include <poll.h>

#include <cerrno>
#include <cstdint>
#include <ctime>
#include <limits>
#include <string>
#include <system_error>

// poll() on one or two descriptors with a timeout in nanoseconds, restarted after signals, and
// the other small helpers the socket code shares.
namespace smx::net::detail {

[[nodiscard]] inline int timeoutMs(std::int64_t timeoutNs) {
  if (timeoutNs <= 0) {
    return 0;
  }
  const std::int64_t ms = (timeoutNs + 999'999) / 1'000'000;
  return ms > std::numeric_limits<int>::max() ? std::numeric_limits<int>::max()
                                              : static_cast<int>(ms);
}

// "what: <errno's text>" (thread-safe, unlike strerror).
[[nodiscard]] inline std::string systemError(const std::string& what, int err = errno) {
  return what + ": " + std::system_category().message(err);
}

// A non-blocking call that could not proceed now (Linux: EWOULDBLOCK is EAGAIN).
static_assert(EAGAIN == EWOULDBLOCK);
[[nodiscard]] inline bool wouldBlock(int err) {
  return err == EAGAIN || err == EINTR;
}

// CLOCK_MONOTONIC in nanoseconds (the HAL's clock is not reachable from here).
[[nodiscard]] inline std::int64_t monotonicNs() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return std::int64_t{now.tv_sec} * 1'000'000'000 + now.tv_nsec;
}

// Returns poll()'s result; -1 with errno on failure.
[[nodiscard]] inline int pollRetry(pollfd* fds, nfds_t count, std::int64_t timeoutNs) {
  int result = 0;
  do {
    result = ::poll(fds, count, timeoutMs(timeoutNs));
  } while (result < 0 && errno == EINTR);
  return result;
}

}  // namespace smx::net::detail
