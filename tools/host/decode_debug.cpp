#include "decode_debug.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "colour_map.hpp"

namespace smx::host {

sim::RgbImage renderDepth(algo::ConstDepthPlane depth, std::uint16_t nearUnits,
                          std::uint16_t farUnits) {
  sim::RgbImage image = blankImage(depth.width(), depth.height());
  if (nearUnits == 0 && farUnits == 0) {
    std::vector<std::uint16_t> valid;
    for (int y = 0; y < depth.height(); ++y) {
      for (int x = 0; x < depth.width(); ++x) {
        if (depth(x, y) != algo::kNoDepth) {
          valid.push_back(depth(x, y));
        }
      }
    }
    if (valid.empty()) {
      return image;
    }
    std::sort(valid.begin(), valid.end());
    nearUnits = valid[valid.size() / 100];
    farUnits = valid[valid.size() - 1 - valid.size() / 100];
  }
  const double span = std::max(1.0, static_cast<double>(farUnits) - nearUnits);
  for (int y = 0; y < depth.height(); ++y) {
    for (int x = 0; x < depth.width(); ++x) {
      const std::uint16_t z = depth(x, y);
      if (z != algo::kNoDepth) {
        const double t = std::clamp((z - nearUnits) / span, 0.0, 1.0);
        image.pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(depth.width()) +
                     static_cast<std::size_t>(x)] = hueColour(t * 2.0 / 3.0, 1.0);
      }
    }
  }
  return image;
}

sim::RgbImage renderStripes(algo::ConstStripePlane stripe) {
  sim::RgbImage image = blankImage(stripe.width(), stripe.height());
  constexpr double kGoldenRatio = 0.618033988749895;  // neighbouring stripes far apart in hue
  for (int y = 0; y < stripe.height(); ++y) {
    for (int x = 0; x < stripe.width(); ++x) {
      const algo::StripeQ16 s = stripe(x, y);
      if (s == algo::kNoStripe) {
        continue;
      }
      const double v = static_cast<double>(s) / algo::kStripeOne;
      const double index = std::floor(v);
      image.pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(stripe.width()) +
                   static_cast<std::size_t>(x)] =
          hueColour(index * kGoldenRatio, 0.5 + 0.5 * (v - index));
    }
  }
  return image;
}

}  // namespace smx::host
