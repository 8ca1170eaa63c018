#pragma once

#include <cstddef>
#include <cstdint>
#include <expected>

#include "smx/hal/unique_fd.hpp"

// The system calls a V4L2 camera makes, behind an interface so that the camera's state machine
// can be tested against a simulated driver (tests/hal_linux). Each call is wrapped once and
// reports failure as -errno (libcamera's V4L2Device::ioctl); the caller adds context.
namespace smx::lnx {

class V4l2Io {
 public:
  virtual ~V4l2Io() = default;
  V4l2Io(const V4l2Io&) = delete;
  V4l2Io& operator=(const V4l2Io&) = delete;

  // A file descriptor (>= 0) or -errno.
  [[nodiscard]] virtual int open(const char* path, int flags) = 0;
  virtual int close(int fd) = 0;
  // 0 (or the driver's non-negative result) or -errno.
  [[nodiscard]] virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
  // The mapping, or -errno.
  [[nodiscard]] virtual std::expected<void*, int> mmap(int fd, std::size_t length,
                                                       std::int64_t offset) = 0;
  virtual int munmap(void* address, std::size_t length) = 0;
  // Waits at most timeoutNs for `events` on fd: 1 with `revents` filled, 0 on timeout, or -errno.
  [[nodiscard]] virtual int poll(int fd, short events, std::int64_t timeoutNs, short& revents) = 0;
  // CLOCK_MONOTONIC, the clock drivers stamp buffers with.
  [[nodiscard]] virtual std::int64_t nowNs() = 0;

 protected:
  V4l2Io() = default;
};

// Closes through the seam, so that a fake driver sees its descriptors closed.
struct V4l2Close {
  V4l2Io* io = nullptr;
  void operator()(int fd) const { (void)io->close(fd); }
};

// A descriptor from V4l2Io::open, closed once by V4l2Io::close.
using V4l2Fd = hal::BasicUniqueFd<V4l2Close>;

// The real system calls. Stateless. open and ioctl retry EINTR; poll returns -EINTR, since only
// the caller knows how much time is left.
class SystemV4l2Io final : public V4l2Io {
 public:
  SystemV4l2Io() = default;
  [[nodiscard]] int open(const char* path, int flags) override;
  int close(int fd) override;
  [[nodiscard]] int ioctl(int fd, unsigned long request, void* arg) override;
  [[nodiscard]] std::expected<void*, int> mmap(int fd, std::size_t length,
                                               std::int64_t offset) override;
  int munmap(void* address, std::size_t length) override;
  [[nodiscard]] int poll(int fd, short events, std::int64_t timeoutNs, short& revents) override;
  [[nodiscard]] std::int64_t nowNs() override;
};

}  // namespace smx::lnx
