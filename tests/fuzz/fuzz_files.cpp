#include "fuzz_files.hpp"

namespace smx::fuzz {

std::filesystem::path filesDir() {
  return SMX_FUZZ_FILES;
}

}  // namespace smx::fuzz
