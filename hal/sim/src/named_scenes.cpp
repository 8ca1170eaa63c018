#include "smx/sim/named_scenes.hpp"

#include <algorithm>
#include <cstdlib>
#include <system_error>

namespace smx::sim {

namespace fs = std::filesystem;

namespace {

// NOLINTBEGIN(concurrency-mt-unsafe): read at start-up, before any thread exists.
std::string environment(const char* name) {
  const char* value = std::getenv(name);
  return value == nullptr ? std::string() : std::string(value);
}
// NOLINTEND(concurrency-mt-unsafe)

bool isDataDir(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir / "scenes", ec);
}

}  // namespace

std::expected<fs::path, std::string> dataDir() {
  if (auto env = environment("STRIPEMUX_DATA_DIR"); !env.empty()) {
    return fs::path(env);
  }
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) {
    return std::unexpected("the data folder: /proc/self/exe: " + ec.message() +
                           " (set STRIPEMUX_DATA_DIR)");
  }
  const fs::path bin = exe.parent_path();
  // Relative, so that the installed tree may be moved (DESTDIR, dpkg -x, another prefix).
  const fs::path installed = (bin / SMX_DATA_DIR_FROM_BIN).lexically_normal();
  if (isDataDir(installed)) {
    return installed;
  }
  for (fs::path dir = bin; !dir.empty(); dir = dir.parent_path()) {
    if (isDataDir(dir / SMX_BUILD_DATA_DIR)) {
      return dir / SMX_BUILD_DATA_DIR;
    }
    if (dir == dir.parent_path()) {
      break;
    }
  }
  return std::unexpected("the data folder (scenes, example boards) is neither " +
                         installed.string() +
                         " nor a " SMX_BUILD_DATA_DIR " folder of a build tree above " +
                         bin.string() + "; set STRIPEMUX_DATA_DIR");
}

std::expected<fs::path, std::string> sceneDir() {
  if (auto env = environment("STRIPEMUX_SCENES"); !env.empty()) {
    return fs::path(env);
  }
  auto data = dataDir();
  if (!data) {
    return std::unexpected(data.error());
  }
  return *data / "scenes";
}

std::vector<std::string> namedScenes() {
  std::vector<std::string> names;
  const auto dir = sceneDir();
  if (!dir) {
    return names;
  }
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(*dir, ec)) {
    if (entry.path().extension() == ".json") {
      names.push_back(entry.path().stem().string());
    }
  }
  std::ranges::sort(names);
  return names;
}

std::expected<fs::path, std::string> resolveScene(const std::string& arg) {
  if (fs::exists(arg) || arg.find('/') != std::string::npos || arg.ends_with(".json")) {
    return fs::path(arg);
  }
  const auto dir = sceneDir();
  if (!dir) {
    return std::unexpected("scene '" + arg +
                           "': no such file, and no named scenes: " + dir.error());
  }
  const auto named = *dir / (arg + ".json");
  if (fs::exists(named)) {
    return named;
  }
  std::string known;
  for (const auto& n : namedScenes()) {
    known += (known.empty() ? "" : ", ") + n;
  }
  return std::unexpected("scene '" + arg + "': no such file and no named scene of that name" +
                         " (named scenes: " + known + ")");
}

}  // namespace smx::sim
