#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <ranges>
#include <set>
#include <string>
#include <system_error>

#include "smx/update/bundle.hpp"
#include "smx/update/file_io.hpp"

namespace smx::update {
namespace {

namespace fs = std::filesystem;

std::unexpected<UpdateError> ioFail(const fs::path& path, const char* what) {
  return std::unexpected(
      UpdateError{UpdateReason::kIo,
                  path.string() + ": " + what + ": " + std::generic_category().message(errno)});
}

// Creates the file's directories below root (names are checked: no "..", no leading '/') and
// remembers them for the fsync at the end.
std::expected<void, UpdateError> makeParents(const fs::path& root, const std::string& name,
                                             std::set<fs::path>& dirs) {
  for (auto slash = name.find('/'); slash != std::string::npos; slash = name.find('/', slash + 1)) {
    const fs::path dir = root / name.substr(0, slash);
    if (dirs.insert(dir).second && ::mkdir(dir.c_str(), 0755) != 0 && errno != EEXIST) {
      return ioFail(dir, "mkdir");
    }
  }
  return {};
}

}  // namespace

std::expected<void, UpdateError> extractBundle(const VerifiedBundle& bundle,
                                               const fs::path& slotDir) {
  std::error_code ec;
  if (fs::exists(fs::symlink_status(slotDir, ec))) {
    return std::unexpected(
        UpdateError{UpdateReason::kExists, slotDir.string() + ": exists already"});
  }
  const fs::path temp = slotDir.string() + ".tmp";
  fs::remove_all(temp, ec);  // what an interrupted extraction left; remove_all follows no link
  if (ec) {
    return std::unexpected(UpdateError{UpdateReason::kIo, temp.string() + ": " + ec.message()});
  }
  if (::mkdir(temp.c_str(), 0755) != 0) {
    return ioFail(temp, "mkdir");
  }
  std::set<fs::path> dirs;
  for (const auto& file : bundle.info().files) {
    if (auto parents = makeParents(temp, file.name, dirs); !parents) {
      return parents;
    }
    if (auto written = writeNewFile(temp / file.name, bundle.fileBytes(file), file.mode);
        !written) {
      return written;
    }
  }
  // Deepest first, so that each directory's entries are durable before its parent's.
  for (const auto& dir : std::views::reverse(dirs)) {
    if (auto synced = syncDirectory(dir); !synced) {
      return synced;
    }
  }
  if (auto synced = syncDirectory(temp); !synced) {
    return synced;
  }
  if (std::rename(temp.c_str(), slotDir.c_str()) != 0) {
    return ioFail(slotDir, "rename");
  }
  const fs::path parent = slotDir.has_parent_path() ? slotDir.parent_path() : fs::path(".");
  return syncDirectory(parent);
}

}  // namespace smx::update
