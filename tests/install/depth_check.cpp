// depth_check DEPTH.png TRUTH.pfm UNIT_M MIN_COMPLETENESS: a decoded 16-bit depth image against
// the simulator's depth truth. Passes (exit 0) when at least MIN_COMPLETENESS of the truth's
// surface pixels have depth and 95 % of those are within 3 mm; prints both shares either way.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "smx/sim/pfm_io.hpp"
#include "smx/sim/png_io.hpp"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: depth_check DEPTH.png TRUTH.pfm UNIT_M MIN_COMPLETENESS\n");
    return 2;
  }
  const auto depth = smx::sim::readPngGray16(argv[1]);
  const auto truth = smx::sim::readPfm(argv[2]);
  if (!depth || !truth) {
    std::fprintf(stderr, "depth_check: %s\n", (!depth ? depth.error() : truth.error()).c_str());
    return 1;
  }
  if (depth->width != truth->width || depth->height != truth->height || truth->channels != 1) {
    std::fprintf(stderr, "depth_check: depth %dx%d, truth %dx%dx%d\n", depth->width, depth->height,
                 truth->width, truth->height, truth->channels);
    return 1;
  }
  const double unitM = std::stod(argv[3]);
  const double minCompleteness = std::stod(argv[4]);
  int surface = 0;
  int valid = 0;
  int close = 0;
  for (std::size_t i = 0; i < depth->pixels.size(); ++i) {
    const float z = truth->values[i];
    if (!std::isfinite(z)) {
      continue;
    }
    ++surface;
    if (const std::uint16_t d = depth->pixels[i]; d != 0) {
      ++valid;
      close += std::abs(d * unitM - z) <= 0.003 ? 1 : 0;
    }
  }
  const double completeness = surface > 0 ? static_cast<double>(valid) / surface : 0.0;
  const double within3mm = valid > 0 ? static_cast<double>(close) / valid : 0.0;
  std::printf("depth_check: %d surface pixels, completeness %.3f, within 3 mm %.3f\n", surface,
              completeness, within3mm);
  return completeness >= minCompleteness && within3mm >= 0.95 ? 0 : 1;
}
