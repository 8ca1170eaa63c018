#include "smx/update/file_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <string_view>
#include <system_error>
#include <utility>

namespace smx::update {
namespace {

namespace fs = std::filesystem;

UpdateError ioError(const fs::path& path, const char* what) {
  return {UpdateReason::kIo,
          path.string() + ": " + what + ": " + std::generic_category().message(errno)};
}

// Owns a file descriptor for the length of one function.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) {
      ::close(fd_);
    }
  }
  [[nodiscard]] int get() const { return fd_; }
  [[nodiscard]] int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

bool writeAll(int fd, std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    const auto n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) {
      continue;
    }
    if (n <= 0) {
      return false;
    }
    bytes = bytes.subspan(static_cast<std::size_t>(n));
  }
  return true;
}

}  // namespace

std::expected<void, UpdateError> syncDirectory(const fs::path& dir) {
  const Fd fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() < 0 || ::fsync(fd.get()) != 0) {
    return std::unexpected(ioError(dir, "fsync of the directory"));
  }
  return {};
}

namespace {

// writeNewFile() with a step hook: the atomic writer reports the steps between its calls.
std::expected<void, UpdateError> writeNew(const fs::path& path, std::span<const std::byte> bytes,
                                          unsigned mode, const StepHook& onStep) {
  const auto step = [&](std::string_view name) {
    if (onStep) {
      onStep(name);
    }
  };
  Fd fd(::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600));
  if (fd.get() < 0) {
    return std::unexpected(ioError(path, "create"));
  }
  step("temp-created");
  // fchmod, not the open mode: the umask must not decide a firmware file's mode.
  if (::fchmod(fd.get(), mode) != 0 || !writeAll(fd.get(), bytes)) {
    return std::unexpected(ioError(path, "write"));
  }
  step("temp-written");
  if (::fsync(fd.get()) != 0) {
    return std::unexpected(ioError(path, "fsync"));
  }
  step("temp-synced");
  if (::close(fd.release()) != 0) {
    return std::unexpected(ioError(path, "close"));
  }
  return {};
}

}  // namespace

std::expected<void, UpdateError> writeNewFile(const fs::path& path,
                                              std::span<const std::byte> bytes, unsigned mode) {
  return writeNew(path, bytes, mode, {});
}

fs::path tempPathOf(const fs::path& path) {
  return path.string() + ".tmp";
}

std::expected<void, UpdateError> writeFileAtomic(const fs::path& path,
                                                 std::span<const std::byte> bytes, unsigned mode,
                                                 Replace replace, const StepHook& onStep) {
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (replace == Replace::kRefuse && ::access(path.c_str(), F_OK) == 0) {
    return std::unexpected(UpdateError{UpdateReason::kExists, path.string() + ": exists already"});
  }
  const fs::path temp = tempPathOf(path);
  ::unlink(temp.c_str());
  if (auto written = writeNew(temp, bytes, mode, onStep); !written) {
    ::unlink(temp.c_str());
    return written;
  }
  // link() fails when the target exists, so a file appearing since the check is not replaced.
  const bool placed = replace == Replace::kRefuse ? ::link(temp.c_str(), path.c_str()) == 0
                                                  : ::rename(temp.c_str(), path.c_str()) == 0;
  if (!placed) {
    const int error = errno;
    ::unlink(temp.c_str());
    errno = error;
    if (error == EEXIST) {
      return std::unexpected(
          UpdateError{UpdateReason::kExists, path.string() + ": exists already"});
    }
    return std::unexpected(ioError(path, "rename"));
  }
  if (replace == Replace::kRefuse) {
    ::unlink(temp.c_str());
  }
  if (onStep) {
    onStep("renamed");
  }
  auto synced = syncDirectory(dir);
  if (synced && onStep) {
    onStep("dir-synced");
  }
  return synced;
}

std::expected<std::vector<std::byte>, UpdateError> readFile(const fs::path& path,
                                                            std::size_t maxBytes) {
  // O_NONBLOCK: a FIFO in place of the file must not hang the open; it is refused below.
  const Fd fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  struct stat st {};
  if (fd.get() < 0 || ::fstat(fd.get(), &st) != 0) {
    return std::unexpected(ioError(path, "open"));
  }
  if (!S_ISREG(st.st_mode)) {
    return std::unexpected(
        UpdateError{UpdateReason::kMalformed, path.string() + ": not a regular file"});
  }
  if (static_cast<std::uint64_t>(st.st_size) > maxBytes) {
    return std::unexpected(UpdateError{
        UpdateReason::kTooLarge, path.string() + ": " + std::to_string(st.st_size) +
                                     " bytes, more than the limit of " + std::to_string(maxBytes)});
  }
  std::vector<std::byte> bytes(static_cast<std::size_t>(st.st_size));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const auto n = ::read(fd.get(), bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) {
      continue;
    }
    if (n < 0) {
      return std::unexpected(ioError(path, "read"));
    }
    if (n == 0) {
      bytes.resize(done);  // shrank while being read: what is there is what is checked
      break;
    }
    done += static_cast<std::size_t>(n);
  }
  return bytes;
}

std::span<const std::byte> asBytes(const std::string& text) {
  return std::as_bytes(std::span(text.data(), text.size()));
}

}  // namespace smx::update
