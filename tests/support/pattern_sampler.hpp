#pragma once

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/algo/rig.hpp"
#include "smx/algo/stripe_code.hpp"

// Test helper: reads a projector pattern image back by sampling it at each stripe's centre along
// the encoding axis, following the rig.json pattern semantics (not the renderer's code).
namespace smx::test {

struct SampledStripe {
  int index;                    // stripe index the spec puts at this position
  algo::stripe::Colour colour;  // colour found in the image there
};

inline std::optional<algo::stripe::Colour> primaryOf(algo::Rgb8 p) {
  if (p == algo::Rgb8{255, 0, 0})
    return algo::stripe::Colour::kRed;
  if (p == algo::Rgb8{0, 255, 0})
    return algo::stripe::Colour::kGreen;
  if (p == algo::Rgb8{0, 0, 255})
    return algo::stripe::Colour::kBlue;
  return std::nullopt;
}

// Returns the stripes whose centre falls inside the image. A pixel that is not a pure primary
// ends the sampling with an empty result (the image is wrong).
inline std::optional<std::vector<SampledStripe>> sampleAlongAxis(algo::ConstRgbView image,
                                                                 const algo::StripePattern& p) {
  const double a = p.angleDeg * std::numbers::pi / 180.0;
  const double cu = (image.width() - 1) / 2.0;
  const double cv = (image.height() - 1) / 2.0;
  std::vector<SampledStripe> out;
  for (int i = 0; i < algo::stripe::kStripes; ++i) {
    const double along = p.offsetPx + (i + 0.5 - algo::stripe::kStripes / 2.0) * p.stripePx;
    const long u = std::lround(cu + along * std::cos(a));
    const long v = std::lround(cv + along * std::sin(a));
    if (u < 0 || v < 0 || u >= image.width() || v >= image.height()) {
      continue;
    }
    const auto c = primaryOf(image(static_cast<int>(u), static_cast<int>(v)));
    if (!c) {
      return std::nullopt;
    }
    out.push_back({i, *c});
  }
  return out;
}

}  // namespace smx::test
