#pragma once

#include "smx/algo/error.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/rig.hpp"
#include "smx/algo/stripe_code.hpp"

// What a projector shows: the stripe sequence laid across its image along the pattern's encoding
// axis (rig.hpp, StripePattern). Init-time and host code (pattern images, simulator ground truth);
// uses double.
namespace smx::algo {

// Continuous stripe coordinate of projector pixel position (u, v): stripe i covers [i, i+1), so
// floor() gives the stripe index; values outside [0, kStripes) are outside the sequence (black).
[[nodiscard]] double stripeCoordinate(const StripePattern& pattern, int projectorWidth,
                                      int projectorHeight, double u, double v);

// The projected light of a stripe: pure primaries at full level.
[[nodiscard]] constexpr Rgb8 stripeRgb(stripe::Colour c) {
  switch (c) {
    case stripe::Colour::kRed:
      return {255, 0, 0};
    case stripe::Colour::kGreen:
      return {0, 255, 0};
    case stripe::Colour::kBlue:
      return {0, 0, 255};
  }
  return {0, 0, 0};
}

// Stripes whose whole width lies inside the projector image. Fewer than a code window
// (stripe::kWindowStripes) and no stripe of the pattern can be identified.
[[nodiscard]] int visibleStripes(const Projector& projector);

// Fills `out` (projector width × height) with the pattern, each pixel coloured by the stripe at
// its centre.
[[nodiscard]] Result<void> renderPatternImage(const Projector& projector, RgbView out);

}  // namespace smx::algo
