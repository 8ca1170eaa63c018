#include "config_presets.hpp"

#include <array>

namespace smx::host {

namespace {

// confidence_min is 255·(1 − 2e/tolerance) (docs/decode.md): 128 keeps depths whose predicted
// error is under a quarter of the gross tolerance.
constexpr std::array<ConfigPreset, 4> kPresets = {{
    {"fast", "the board's full frame rate, every trusted depth",
     R"({"format": "stripemux-config/1", "fps": 30, "compression": "any", "confidence_min": 1})"},
    {"accurate", "half the frame rate, only depths predicted within a quarter of the tolerance",
     R"({"format": "stripemux-config/1", "fps": 15, "confidence_min": 128})"},
    {"close-range", "objects 0.2 to 0.8 m away; everything farther is dropped",
     R"({"format": "stripemux-config/1", "depth_min_m": 0.2, "depth_max_m": 0.8})"},
    // Four times the light of the simulated camera's 10 ms at unity gain: exposure first (it
    // adds no noise), then gain; 20 ms still fits a frame at 30 fps.
    {"dark-objects", "dark or distant surfaces: longer exposure, some gain, full projector power",
     R"({"format": "stripemux-config/1", "exposure_us": 20000, "gain": 2, "projector_power": 100})"},
}};

}  // namespace

std::span<const ConfigPreset> configPresets() {
  return kPresets;
}

}  // namespace smx::host
