// libFuzzer target for board.json (smx::config::parseBoard): any text is a board or a BoardError,
// never a crash or a sanitizer report. Relative paths in the input (the rig, a replay folder)
// resolve in tests/fuzz/files, where the seeds' rig is.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_files.hpp"
#include "smx/config/board_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto dir = smx::fuzz::filesDir();
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  (void)smx::config::parseBoard(text, dir);
  return 0;
}
