#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "gaussian_blur.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/rig.hpp"

// What the simulated camera's sensor and electronics do to the light that reaches each pixel
// (docs/simulator.md, steps 7 to 12): vignetting, the response curve and the colour mosaic.
namespace smx::sim::detail {

// gain(x, y) = 1 − v·(r/r_corner)², r the distance of pixel centre (x, y) from the principal
// point and r_corner that of the image corner farthest from it (corners at (−½, −½) and
// (W − ½, H − ½)).
class Vignetting {
 public:
  Vignetting(const algo::Camera& camera, double v);
  [[nodiscard]] double gain(int x, int y) const;

 private:
  double v_;
  double cx_;
  double cy_;
  double inverseCorner2_ = 0.0;  // 1 / r_corner²
};

// grey ← 255·(grey/255)^(1/γ) per channel (0 below 0); γ = 1 leaves the image untouched.
void applyResponseGamma(std::vector<RgbF>& linear, double gamma);

// The channel (0 red, 1 green, 2 blue) a colour filter keeps at each site of the 2 × 2 cell,
// row by row from the top left.
struct BayerCell {
  std::array<std::uint8_t, 4> channel{};
  [[nodiscard]] std::size_t at(int x, int y) const {
    return channel[(static_cast<std::size_t>(y) & 1U) * 2U + (static_cast<std::size_t>(x) & 1U)];
  }
};

// The cell of a scene's `bayer` value ("rggb", …); nullopt for "none" or an unknown name.
[[nodiscard]] std::optional<BayerCell> bayerCell(std::string_view pattern);

// Keeps the filter's channel at each pixel, then restores the other two by bilinear
// interpolation: each is the mean of the 3 × 3 neighbours (inside the image) that kept it, rounded
// half up. The kept channel is unchanged.
void mosaicAndDemosaic(algo::RgbView image, const BayerCell& cell);

}  // namespace smx::sim::detail
