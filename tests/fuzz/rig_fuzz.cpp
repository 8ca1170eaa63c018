// libFuzzer target for rig.json (smx::config::parseRig): any text is a rig or a RigError, never
// a crash or a sanitizer report; a rig that parses is written (toJson) and reads back to the
// same text, as rig_json.hpp promises.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "smx/config/rig_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto rig = smx::config::parseRig(text);
  if (!rig) {
    return 0;
  }
  const std::string json = smx::config::toJson(*rig);
  const auto again = smx::config::parseRig(json);
  if (!again || smx::config::toJson(*again) != json) {
    std::abort();
  }
  return 0;
}
