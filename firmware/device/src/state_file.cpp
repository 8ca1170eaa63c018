#include "smx/device/state_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <system_error>

#include "smx/hal/unique_fd.hpp"

namespace smx::device {
namespace {

namespace fs = std::filesystem;

std::string systemError(const std::string& what, const fs::path& path) {
  return what + " " + path.string() + ": " +
         std::error_code(errno, std::generic_category()).message();
}

fs::path tempOf(const fs::path& file) {
  return file.string() + ".tmp";
}

}  // namespace

void crashPoint(std::string_view point) {
  const char* at = std::getenv("SMX_CRASH_AT");  // NOLINT(concurrency-mt-unsafe): read only
  if (at != nullptr && point == at) {
    std::raise(SIGKILL);
  }
}

std::expected<void, std::string> writeStateFile(const fs::path& file, std::string_view text,
                                                std::string_view what) {
  const auto step = [&](std::string_view name) {
    crashPoint(std::string(what) + "." + std::string(name));
  };
  const fs::path temp = tempOf(file);
  const hal::UniqueFd fd(::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (!fd.valid()) {
    return std::unexpected(systemError("cannot create", temp));
  }
  step("temp-created");
  for (std::size_t done = 0; done < text.size();) {
    const ssize_t n = ::write(fd.get(), text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) {
      continue;
    }
    if (n <= 0) {
      const std::string error = systemError("cannot write", temp);
      ::unlink(temp.c_str());
      return std::unexpected(error);
    }
    done += static_cast<std::size_t>(n);
  }
  step("temp-written");
  if (::fsync(fd.get()) != 0) {
    const std::string error = systemError("cannot flush", temp);
    ::unlink(temp.c_str());
    return std::unexpected(error);
  }
  step("temp-synced");
  if (::rename(temp.c_str(), file.c_str()) != 0) {
    const std::string error = systemError("cannot rename the new file over", file);
    ::unlink(temp.c_str());
    return std::unexpected(error);
  }
  step("renamed");
  const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
  const hal::UniqueFd dirFd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (!dirFd.valid() || ::fsync(dirFd.get()) != 0) {
    return std::unexpected(systemError("cannot flush the directory", dir));
  }
  step("dir-synced");
  return {};
}

bool removeInterruptedWrite(const fs::path& file) {
  std::error_code ec;
  return fs::remove(tempOf(file), ec);
}

}  // namespace smx::device
