#include "smx/sim/named_scenes.hpp"

#include <algorithm>
#include <cstdlib>
#include <system_error>

namespace smx::sim {

namespace fs = std::filesystem;

fs::path sceneDir() {
  // NOLINTNEXTLINE(concurrency-mt-unsafe): read at start-up, before any thread exists.
  if (const char* env = std::getenv("STRIPEMUX_SCENES"); env != nullptr && *env != '\0') {
    return env;
  }
  return SMX_SCENE_DIR;
}

std::vector<std::string> namedScenes() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(sceneDir(), ec)) {
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
  const auto named = sceneDir() / (arg + ".json");
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
