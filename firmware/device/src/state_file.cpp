#include "smx/device/state_file.hpp"

#include <csignal>
#include <cstdlib>
#include <system_error>

#include "smx/update/file_io.hpp"

namespace smx::device {

namespace fs = std::filesystem;

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
  if (auto written = update::writeFileAtomic(file, std::as_bytes(std::span(text)), 0644,
                                             update::Replace::kAllow, step);
      !written) {
    return std::unexpected(written.error().message);
  }
  return {};
}

bool removeInterruptedWrite(const fs::path& file) {
  std::error_code ec;
  return fs::remove(update::tempPathOf(file), ec);
}

}  // namespace smx::device
