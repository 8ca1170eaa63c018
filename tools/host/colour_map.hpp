#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/sim/png_io.hpp"

// Small colour helpers shared by the debug renderings.
namespace smx::host {

// A black image.
[[nodiscard]] inline sim::RgbImage blankImage(int width, int height) {
  return {
      width, height,
      std::vector<algo::Rgb8>(static_cast<std::size_t>(width) * static_cast<std::size_t>(height),
                              algo::Rgb8{0, 0, 0})};
}

// The colour of hue (turns: 0 red, ⅓ green, ⅔ blue; wraps) at full saturation and value 0…1.
[[nodiscard]] inline algo::Rgb8 hueColour(double hue, double value) {
  const double h = (hue - std::floor(hue)) * 6.0;  // sextants of the colour wheel
  const double f = h - std::floor(h);
  const auto c = [value](double v) {
    return static_cast<std::uint8_t>(std::clamp(std::lround(255.0 * v * value), 0L, 255L));
  };
  switch (static_cast<int>(h)) {
    case 0:
      return {c(1), c(f), c(0)};
    case 1:
      return {c(1 - f), c(1), c(0)};
    case 2:
      return {c(0), c(1), c(f)};
    case 3:
      return {c(0), c(1 - f), c(1)};
    case 4:
      return {c(f), c(0), c(1)};
    default:
      return {c(1), c(0), c(1 - f)};
  }
}

}  // namespace smx::host
