// depth_check DEPTH.png TRUTH.pfm UNIT_M MIN_COMPLETENESS: a decoded 16-bit depth image against
// the simulator's depth truth. Passes (exit 0) when at least MIN_COMPLETENESS of the truth's
// surface pixels have depth and 95 % of those are within 3 mm; prints both shares either way.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "smx/eval/depth_eval.hpp"
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
  const auto truthView =
      *smx::algo::ImageView<const float>::packed(truth->values, truth->width, truth->height);
  const std::vector<std::uint8_t> everywhere(depth->pixels.size(), 1);
  const auto region =
      *smx::algo::ImageView<const std::uint8_t>::packed(everywhere, depth->width, depth->height);
  const auto score = smx::eval::scoreDepth(depth->view(), truthView, region, {.depthUnitM = unitM});
  int close = 0;
  for (const float errorMm : smx::eval::depthErrorMapMm(depth->view(), truthView, unitM)) {
    close += std::abs(errorMm) <= 3.0F ? 1 : 0;  // false for NaN: no depth or no surface
  }
  const double within3mm = score.valid > 0 ? static_cast<double>(close) / score.valid : 0.0;
  std::printf("depth_check: %d surface pixels, completeness %.3f, within 3 mm %.3f\n",
              score.regionPixels, score.completeness, within3mm);
  return score.completeness >= minCompleteness && within3mm >= 0.95 ? 0 : 1;
}
