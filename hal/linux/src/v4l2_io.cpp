#include "smx/linux/v4l2_io.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <ctime>

namespace smx::lnx {

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

}  // namespace

int SystemV4l2Io::open(const char* path, int flags) {
  int fd = -1;
  do {
    fd = ::open(path, flags);
  } while (fd < 0 && errno == EINTR);
  return fd < 0 ? -errno : fd;
}

int SystemV4l2Io::close(int fd) {
  // Not retried on EINTR: Linux releases the descriptor even then.
  return ::close(fd) == 0 ? 0 : -errno;
}

int SystemV4l2Io::ioctl(int fd, unsigned long request, void* arg) {
  int result = -1;
  do {
    result = ::ioctl(fd, request, arg);
  } while (result < 0 && errno == EINTR);
  return result < 0 ? -errno : result;
}

std::expected<void*, int> SystemV4l2Io::mmap(int fd, std::size_t length, std::int64_t offset) {
  void* address =
      ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, static_cast<off_t>(offset));
  if (address == MAP_FAILED) {
    return std::unexpected(-errno);
  }
  return address;
}

int SystemV4l2Io::munmap(void* address, std::size_t length) {
  return ::munmap(address, length) == 0 ? 0 : -errno;
}

int SystemV4l2Io::poll(int fd, short events, std::int64_t timeoutNs, short& revents) {
  pollfd entry{.fd = fd, .events = events, .revents = 0};
  const std::int64_t ns = timeoutNs < 0 ? 0 : timeoutNs;
  const timespec timeout{.tv_sec = static_cast<time_t>(ns / kNsPerS),
                         .tv_nsec = static_cast<long>(ns % kNsPerS)};
  // ppoll, not poll: the timeout keeps nanosecond resolution. An EINTR is returned to the
  // caller's loop, which recomputes the time left.
  const int result = ::ppoll(&entry, 1, &timeout, nullptr);
  if (result < 0) {
    return -errno;
  }
  revents = entry.revents;
  return result;
}

std::int64_t SystemV4l2Io::nowNs() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * kNsPerS + now.tv_nsec;
}

}  // namespace smx::lnx
