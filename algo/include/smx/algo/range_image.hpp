#pragma once

#include <cstdint>
#include <limits>

#include "smx/algo/image_view.hpp"

// What decoding hands to triangulation, and what triangulation and merging produce, per camera
// pixel (docs/decode.md).
namespace smx::algo {

// Decoded stripe coordinate of one projector's pattern at a camera pixel, in stripe units, Q16:
// stripe k of the sequence covers [k, k+1) · kStripeOne, so the boundary between stripes k−1 and
// k (boundary level k) lies at k · kStripeOne. The same coordinate as the simulator's `stripe`
// truth (algo::stripeCoordinate). kNoStripe where nothing was decoded.
using StripeQ16 = std::int32_t;
inline constexpr StripeQ16 kStripeOne = 1 << 16;
inline constexpr StripeQ16 kNoStripe = std::numeric_limits<std::int32_t>::min();
using StripePlane = ImageView<StripeQ16>;
using ConstStripePlane = ImageView<const StripeQ16>;

// Range: z in the camera frame, in depth units (depthUnitM metres each), 0 = no data — the Z16 +
// depth-scale convention of depth cameras.
inline constexpr std::uint16_t kNoDepth = 0;
inline constexpr double kDefaultDepthUnitM = 0.0001;
inline constexpr double kMaxDepthUnits = 65535;

// The farthest z a range image in `depthUnitM` stores; anything beyond is lost (kNoDepth).
[[nodiscard]] constexpr double maxStoredDepthM(double depthUnitM) {
  return kMaxDepthUnits * depthUnitM;
}

// A scan reaches beyond the distance the rig is set up for (its nominal depth): the back of the
// object, the wall behind it. A depth unit must store at least this many times that distance.
inline constexpr double kWorkingRangeFactor = 2.0;

// The smallest depth unit that stores kWorkingRangeFactor × nominalDepthM.
[[nodiscard]] constexpr double minDepthUnitM(double nominalDepthM) {
  return kWorkingRangeFactor * nominalDepthM / kMaxDepthUnits;
}
using DepthPlane = ImageView<std::uint16_t>;
using ConstDepthPlane = ImageView<const std::uint16_t>;

}  // namespace smx::algo
