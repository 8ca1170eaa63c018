#pragma once

#include <unistd.h>

#include <utility>

// Owns a file descriptor; closes it once. The closer is a parameter so that a backend whose
// system calls go through a test seam (hal/linux's V4l2Io) closes through the seam too: a fake
// driver's descriptors are not the process's, and ::close on them would close someone else's.
namespace smx::hal {

struct SystemClose {
  void operator()(int fd) const noexcept { ::close(fd); }
};

template <class Closer>
class BasicUniqueFd {
 public:
  BasicUniqueFd() = default;
  explicit BasicUniqueFd(int fd, Closer closer = Closer{}) : fd_(fd), closer_(std::move(closer)) {}
  ~BasicUniqueFd() { reset(); }
  BasicUniqueFd(BasicUniqueFd&& other) noexcept
      : fd_(std::exchange(other.fd_, -1)), closer_(std::move(other.closer_)) {}
  BasicUniqueFd& operator=(BasicUniqueFd&& other) noexcept {
    if (this != &other) {
      reset();
      fd_ = std::exchange(other.fd_, -1);
      closer_ = std::move(other.closer_);
    }
    return *this;
  }
  BasicUniqueFd(const BasicUniqueFd&) = delete;
  BasicUniqueFd& operator=(const BasicUniqueFd&) = delete;

  [[nodiscard]] int get() const { return fd_; }
  [[nodiscard]] bool valid() const { return fd_ >= 0; }
  // Closes the descriptor held (if any) and takes `fd`, closed later by the same closer.
  void reset(int fd = -1) {
    if (fd_ >= 0) {
      closer_(fd_);
    }
    fd_ = fd;
  }

 private:
  int fd_ = -1;
  [[no_unique_address]] Closer closer_{};
};

using UniqueFd = BasicUniqueFd<SystemClose>;

}  // namespace smx::hal
