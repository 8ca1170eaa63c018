#pragma once

#include <span>
#include <string_view>

// Named settings shipped with the host tool (`stripemux config apply NAME`, docs/config.md).
// A preset changes only its own settings: an installed rig and the others stay.
namespace smx::host {

struct ConfigPreset {
  std::string_view name;
  std::string_view summary;
  std::string_view json;  // a stripemux-config/1 document
};

[[nodiscard]] std::span<const ConfigPreset> configPresets();

}  // namespace smx::host
