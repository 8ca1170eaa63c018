#pragma once

// What trustDepth() and its one-pass schedule triangulateTrusted() share (depth_trust.hpp): the
// argument checks and the confidence. Internal to src/frame.

#include <cstdint>

#include "smx/algo/depth_trust.hpp"

namespace smx::algo {

// Every plane the triangulator's size, and the parameters in range; errors name the problem.
[[nodiscard]] Result<void> checkTrustArguments(const Triangulator& triangulator,
                                               ConstStripePlane stripe, DepthPlane depth,
                                               ImageView<std::uint8_t> confidence,
                                               const DepthTrustParams& params);

// The confidence of a depth z with predicted error spread / 2, or 0 when it is not trusted.
inline std::uint8_t confidenceOf(std::int64_t spread, std::int32_t z, const DepthTrustParams& p) {
  if (z < p.nearUnits || z > p.farUnits) {
    return 0;
  }
  const std::int64_t tol2 = 2 * std::int64_t{p.tolerance.at(z)};
  const std::int64_t scaled = spread * p.errorMargin;
  if (scaled > tol2) {
    return 0;
  }
  const std::int64_t c = 255 - (255 * scaled) / tol2;
  return static_cast<std::uint8_t>(c < 1 ? 1 : c);
}

}  // namespace smx::algo
