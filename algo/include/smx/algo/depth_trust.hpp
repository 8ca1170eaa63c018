#pragma once

#include <cstdint>

#include "smx/algo/error.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/range_image.hpp"
#include "smx/algo/triangulation.hpp"

// Which depths of one projector–camera pair can be trusted (docs/decode.md, "Trust and
// confidence"): a pixel keeps its depth only where its stripes are wide enough for the detector
// to separate and where the boundary localisation error of the detector moves the depth by well
// under the gross tolerance. Both limits come from the detector and the triangulation, not from
// a scene:
//   - |∇s|, stripes per camera pixel, from the stripe plane's neighbours (central differences,
//     one-sided where a neighbour has no coordinate; none on an axis: no depth), its magnitude as
//     max(a, 7/8·a + 1/2·b) with a ≥ b the axes' magnitudes (within 4 % of the Euclidean norm);
//   - resolvable: 1 / |∇s| ≥ minStripeWidthQ8 / 256 px;
//   - predicted error: e = |z(s + |∇s|·δ) − z(s)| with δ = boundaryErrorQ8 / 256 px
//     (Triangulator::depthAt once more: exact for the tables; the central difference would
//     differ only in second order), kept when errorMargin · e ≤ tol(z),
//     tol(z) = max(minUnits, permille ‰ of z), the gross tolerance;
//   - within the rig's working range: nearUnits ≤ z ≤ farUnits (a wrong stripe level moves the
//     depth by many stripes, mostly far out of it);
//   - confidence 255 · (1 − errorMargin · e / tol(z)), clamped to 1…255 (0: no depth).
// The defaults and where they come from: docs/decode.md, "Trust and confidence".
//
// Numerics: s Q16, gradients and |∇s| int64 (< 2^25), e Q16 rounded half up; the comparison and
// the confidence in int64. Integer only, no heap.
namespace smx::algo {

// The gross tolerance max(minUnits, permille ‰ of z), in depth units.
struct DepthTolerance {
  int minUnits = 50;  // 5 mm in the default depth unit (prepareCameraPipeline rescales it)
  int permille = 10;

  [[nodiscard]] std::int32_t at(std::int32_t z) const {
    const std::int32_t relative = z * permille / 1000;
    return relative > minUnits ? relative : minUnits;
  }
};

// The gross tolerance's absolute part, metres (docs/results.md: max(5 mm, 1 % z)).
inline constexpr double kGrossToleranceM = 0.005;

struct DepthTrustParams {
  int boundaryErrorQ8 = 54;    // δ = 0.21 px: bounds the decoded boundaries' position error (1σ)
  int minStripeWidthQ8 = 640;  // 2.5 px: narrower stripes are not separated by the detector
  int errorMargin = 2;         // 2δ (≥ 3σ as measured) stays inside the tolerance
  DepthTolerance tolerance;
  // The working range in depth units; prepareCameraPipeline sets it to kFitNearFactor …
  // kWorkingRangeFactor times the nominal depth. The defaults keep every depth.
  int nearUnits = 1;
  int farUnits = 65535;
};

// Range-checks the parameters; errors name the field.
[[nodiscard]] Result<void> validateDepthTrust(const DepthTrustParams& params);

// In place on `depth` (that pair's range image, from `triangulator` and `stripe`): depths that
// cannot be trusted become kNoDepth; `confidence` gets 1…255 where depth stays, 0 elsewhere.
// All planes the triangulator's size.
[[nodiscard]] Result<void> trustDepth(const Triangulator& triangulator, ConstStripePlane stripe,
                                      DepthPlane depth, ImageView<std::uint8_t> confidence,
                                      const DepthTrustParams& params);

// Triangulator::run() into `depth` followed by trustDepth(), in one pass: the same planes bit for
// bit (the schedule; those two are the reference).
[[nodiscard]] Result<void> triangulateTrusted(const Triangulator& triangulator,
                                              ConstStripePlane stripe, DepthPlane depth,
                                              ImageView<std::uint8_t> confidence,
                                              const DepthTrustParams& params);

}  // namespace smx::algo
