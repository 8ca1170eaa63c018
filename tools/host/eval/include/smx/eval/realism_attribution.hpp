#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "smx/algo/image_view.hpp"
#include "smx/algo/range_image.hpp"
#include "smx/eval/boundary_eval.hpp"
#include "smx/eval/sim_frame.hpp"

// What stops a realism run from meeting its targets (docs/results.md, "What stops the targets"):
// every pixel of the scored regions gets the conditions below, computed from the truth and the
// camera image alone (never from the decoder's output). A pixel's cause is the first condition
// it meets, in this order; "other" when it meets none. Host code, double precision.
//
//   narrow   some projector lighting the pixel has stripes narrower than kNarrowStripePx in the
//            camera (1 / |∇s| of the truth stripe plane, stripeGradient), or ∇s undefined there;
//   single   exactly one projector lights the pixel (the merge has no second opinion);
//   dim      the camera image's local contrast is low: of the 3 × 3 box means centred within
//            kDimWindowRadiusPx of the pixel (boxes inside the image), max − min of each colour
//            channel is below kDimContrastDn (the box keeps sensor noise from passing for
//            contrast). The truth does not say which object (and so which albedo) a pixel sees,
//            so dark and saturated albedo count here through the contrast they leave;
//   grazing  the truth surface normal (cross product of the central differences of the truth
//            depth's camera-frame points, distortion removed; undefined where a neighbour has
//            no depth) is more than kGrazingDeg from the camera ray, or from the ray of every
//            projector lighting the pixel;
//   edge     within kNearEdgePx (Euclidean) of a depth discontinuity of the truth (as
//            discontinuityBand defines it, realism_eval.hpp);
//   triple   three projectors light the pixel (three stripe orientations to separate);
//   other    none of the above.
//
// Counted pixels: outside band = the run's outside-band region, missing = resolvable-region
// pixels without depth; gross as depth_eval.hpp defines it. The "without" figures remove every
// pixel that meets a condition, whatever its place in the order.
namespace smx::eval {

enum class Cause : std::uint8_t { kNarrow, kSingle, kDim, kGrazing, kEdge, kTriple, kOther };
inline constexpr int kCauses = 7;
inline constexpr int kNamedCauses = 6;  // all but kOther

inline constexpr double kNarrowStripePx = 3.0;
inline constexpr int kDimWindowRadiusPx = 3;
inline constexpr int kDimContrastDn = 30;
inline constexpr double kGrazingDeg = 70.0;
inline constexpr int kNearEdgePx = 8;

[[nodiscard]] const char* causeName(Cause c);

// Bit (1 << Cause) per named condition the pixel meets; nearEdge: discontinuityBand(truth depth,
// kNearEdgePx).
[[nodiscard]] unsigned pixelConditions(const SimFrame& frame, int camera, const Mask& nearEdge,
                                       int x, int y);
[[nodiscard]] Cause firstCause(unsigned conditions);

// Pixels of one region with a finite truth depth: how many, how many have depth, how many of
// those are gross.
struct CauseTally {
  int region = 0;
  int valid = 0;
  int gross = 0;
  [[nodiscard]] int missing() const { return region - valid; }
};

struct Attribution {
  std::array<CauseTally, kCauses> outsideBand{};  // by first cause
  std::array<CauseTally, kCauses> resolvable{};
  std::array<CauseTally, kNamedCauses> outsideBandWith{};  // by condition met, any order
  std::array<CauseTally, kNamedCauses> resolvableWith{};
};

[[nodiscard]] Attribution attributeRun(const SimFrame& frame, int camera,
                                       algo::ConstDepthPlane merged, const Mask& outsideBand,
                                       const Mask& resolvable,
                                       double depthUnitM = algo::kDefaultDepthUnitM);
[[nodiscard]] Attribution sumAttributions(std::span<const Attribution> runs);

// Shares of the gross outside-band and of the missing resolvable pixels per first cause (0 when
// there are none), and the figures gross / valid outside the band and valid / region of the
// resolvable pixels with every pixel meeting condition c removed (c = kOther: every pixel meeting
// any named condition; nullopt: none removed).
[[nodiscard]] double grossShare(const Attribution& a, Cause c);
[[nodiscard]] double missingShare(const Attribution& a, Cause c);
[[nodiscard]] double grossRateWithout(const Attribution& a, std::optional<Cause> c);
[[nodiscard]] double completenessWithout(const Attribution& a, std::optional<Cause> c);

}  // namespace smx::eval
