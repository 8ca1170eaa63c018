#include "source_dir.hpp"

namespace smx::test {

const std::filesystem::path& sourceDir() {
  static const std::filesystem::path kDir = SMX_SOURCE_DIR;
  return kDir;
}

}  // namespace smx::test
