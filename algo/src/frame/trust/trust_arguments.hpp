#pragma once

// The argument checks trustDepth() and its one-pass schedule triangulateTrusted() share
// (depth_trust.hpp). Internal to src/frame.

#include <cstdint>

#include "smx/algo/depth_trust.hpp"

namespace smx::algo {

// Every plane the triangulator's size, and the parameters in range; errors name the problem.
[[nodiscard]] Result<void> checkTrustArguments(const Triangulator& triangulator,
                                               ConstStripePlane stripe, DepthPlane depth,
                                               ImageView<std::uint8_t> confidence,
                                               const DepthTrustParams& params);

}  // namespace smx::algo
