// libFuzzer target for config.json (smx::config::parseDeviceConfig, docs/config.md): any text is
// a configuration or a FieldError, never a crash or a sanitizer report. Checked against the
// simulated board, whose rig the seeds hold.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "fuzz_files.hpp"
#include "smx/config/device_config.hpp"

namespace {

const smx::config::Board& simBoard() {
  static const smx::config::Board board = [] {
    auto loaded = smx::config::loadBoard(smx::fuzz::filesDir() / "../../../boards/sim");
    if (!loaded) {
      std::abort();  // the fuzz build's source tree is broken, not the input
    }
    return *loaded;
  }();
  return board;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto config = smx::config::parseDeviceConfig(text, simBoard());
  if (config) {
    // What is stored must read back: the daemon restarts from it.
    (void)smx::config::toJson(*config);
    (void)smx::config::effectiveJson(*config, simBoard());
  }
  return 0;
}
