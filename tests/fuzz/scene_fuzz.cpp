// libFuzzer target for scene.json (smx::config::parseScene): any text is a scene or a SceneError,
// never a crash or a sanitizer report. Relative mesh and texture paths in the input resolve in
// tests/fuzz/files, where the seeds' small meshes and texture are.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_files.hpp"
#include "smx/config/scene_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto dir = smx::fuzz::filesDir();
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  (void)smx::config::parseScene(text, dir);
  return 0;
}
