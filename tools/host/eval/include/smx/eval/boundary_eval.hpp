#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "smx/algo/boundary_map.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/stripe_code.hpp"

// Evaluation (stripemux eval, accuracy tests): scores the stripe boundaries and encoding directions
// found by orientation demultiplexing (algo::Boundary / algo::ConstDirectionPlane of one projector
// and camera) against the simulator's exact ground truth for that projector (the `stripe` plane,
// docs/simulator.md). Host code: double precision, allocates, throws std::invalid_argument on
// misuse (planes of different sizes), so a misused helper fails the calling test with a message.
//
// Definitions (s = truth stripe plane, float, NaN where the projector does not light the point;
// stripe k occupies s ∈ [k, k+1); image coordinates x right, y down, pixel (x, y) is the centre):
//
// Truth gradient at pixel p (stripeGradient):
//   s(p) must be finite. Per axis: central difference (s(p+1) − s(p−1)) / 2 when both neighbours
//   are inside the image and finite, else the one-sided difference to the finite neighbour, else
//   undefined (an out-of-image neighbour counts as NaN). |∇s| (stripes per pixel) must be
//   ≥ kMinStripesPerPx. ĝ = ∇s / |∇s| is the true encoding direction (towards growing stripe
//   index).
//
// True boundary (trueBoundaryAt): pixel p owns level k = ⌊s(p) + ½⌋ (round half up) when ĝ(p) is
//   defined, 1 ≤ k ≤ 197 and the signed distance along ĝ from the centre to the level,
//   δ = (k − s(p)) / |∇s(p)| px, satisfies −½ ≤ δ < ½. Its transition, read along +ĝ, is
//   transitionBetween(kSequence[k−1], kSequence[k]). Ownership is a property of the truth alone
//   (independent of the region); only owners inside the region are counted.
//
// A detected boundary at pixel q (Boundary::present(), region(q) ≠ 0), with offset o and direction
//   d̂(q) = (cos, sin) of direction(q) · 2π / 65536:
//   - position P = q + (o / 256)·d̂;
//   - s_det = bilinear interpolation of s at P when the 4 pixels around P are in the image and
//     finite, else s(q) + (o / 256)·(∇s(q)·d̂); when s(q) or ∇s(q) is undefined the detection has
//     no truth (counted in detectedWithoutTruth, never matched);
//   - level k = ⌊s_det + ½⌋, position error e = (s_det − k) / |∇s(q)| px (signed, along ĝ);
//   - matched when 1 ≤ k ≤ 197, |e| ≤ tolerancePx and some pixel in the 3×3 neighbourhood of q
//     (q included, clipped to the image) owns level k;
//   - class correct when matched and its transition code equals 1 + the true transition of k
//     (a code > 6 is invalid: counted in invalidTransitions, never class correct);
//   - wrong direction sign when ĝ(q) is defined and d̂·ĝ(q) < 0 (counted for every detection).
// Recall    = owners p in the region with some detection q in p's 3×3 neighbourhood (in region)
//             matched to p's level / owners in the region.
// Precision = matched / detected (in region).   Class accuracy = class correct / matched.
// Ratios of empty sets are 1.0 and position statistics of an empty set are 0: check the counts.
namespace smx::eval {

inline constexpr double kMinStripesPerPx = 1e-4;  // |∇s| below this: direction undefined
inline constexpr int kFirstLevel = 1;
inline constexpr int kLastLevel = algo::stripe::kStripes - 1;  // 197

// An owning uint8 plane (0 = out, else in), tightly packed.
struct Mask {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;

  [[nodiscard]] static Mask filled(int width, int height, std::uint8_t value);
  [[nodiscard]] algo::ImageView<const std::uint8_t> view() const;
  [[nodiscard]] algo::ImageView<std::uint8_t> mutableView();
  [[nodiscard]] std::uint8_t& at(int x, int y);
  [[nodiscard]] std::uint8_t at(int x, int y) const;
  [[nodiscard]] int count() const;  // pixels ≠ 0
};

// ∇s at one pixel (see the definitions above).
struct StripeGradient {
  double gx = 0;                                              // ∂s/∂x, stripes per pixel
  double gy = 0;                                              // ∂s/∂y
  double magnitude = 0;                                       // |∇s|
  [[nodiscard]] double ux() const { return gx / magnitude; }  // ĝ
  [[nodiscard]] double uy() const { return gy / magnitude; }
};
[[nodiscard]] std::optional<StripeGradient> stripeGradient(algo::ImageView<const float> stripe,
                                                           int x, int y);

// The median of 1 / |∇s| (stripe width in camera pixels) over every `step`-th pixel of each
// `step`-th row where the truth has a gradient; 0 where it has none.
[[nodiscard]] double medianStripeWidthPx(algo::ImageView<const float> stripe, int step = 1);

struct TrueBoundary {
  int level = 0;                          // k, the boundary between stripes k−1 and k
  double deltaPx = 0;                     // δ, from the pixel centre along ĝ
  algo::stripe::Transition transition{};  // read along +ĝ
};
[[nodiscard]] std::optional<TrueBoundary> trueBoundaryAt(algo::ImageView<const float> stripe, int x,
                                                         int y);

// The raw BinAngle of a direction plane as radians, and back (rounded, wrapped to a turn).
[[nodiscard]] double directionRadians(std::uint16_t raw);
[[nodiscard]] std::uint16_t directionRaw(double radians);

struct ScoreOptions {
  double tolerancePx = 1.0;  // max |e| of a matched detection
};

struct BoundaryScore {
  int trueBoundaries = 0;        // owners in the region
  int recalled = 0;              // of those, found by a matched detection in their 3×3
  int detected = 0;              // present detections in the region
  int matched = 0;               // of those, matched to a level
  int matchedAtOwner = 0;        // of those, at a pixel that itself owns the level
  int classCorrect = 0;          // of the matched, with the true transition
  int invalidTransitions = 0;    // detections with a code > 6
  int detectedWithoutTruth = 0;  // detections where s(q) or ∇s(q) is undefined
  int wrongDirectionSign = 0;    // detections with d̂·ĝ < 0

  double recall = 1.0;
  double precision = 1.0;
  double classAccuracy = 1.0;
  double positionRmsPx = 0;     // of e over the matched
  double positionMeanPx = 0;    // signed bias of e
  double positionMaxAbsPx = 0;  // max |e|

  // confusion[true transition][detected transition] over the matched with a valid code.
  std::array<std::array<int, algo::stripe::kTransitions>, algo::stripe::kTransitions> confusion{};
};

// All planes must have the same size.
[[nodiscard]] BoundaryScore scoreBoundaries(algo::ConstBoundaryPlane detected,
                                            algo::ConstDirectionPlane direction,
                                            algo::ImageView<const float> stripe,
                                            algo::ImageView<const std::uint8_t> region,
                                            const ScoreOptions& options = {});

// Unsigned angle between d̂ and ĝ, degrees in [0, 180], over region pixels where ĝ is defined.
// Percentiles interpolate linearly between order statistics (sorted[(n − 1)·q]); count 0 gives
// all zeros.
struct AngleStats {
  int count = 0;
  double medianDeg = 0;
  double p95Deg = 0;
  double maxDeg = 0;
  double fractionOver90 = 0;  // sign errors
};
[[nodiscard]] AngleStats scoreDirections(algo::ConstDirectionPlane direction,
                                         algo::ImageView<const float> stripe,
                                         algo::ImageView<const std::uint8_t> region);

// Regions. A lit plane is "lit" where ≠ 0; all planes of one call must have the same size
// (an empty span gives an empty mask).
[[nodiscard]] Mask litByExactly(std::span<const algo::ImageView<const std::uint8_t>> lits, int n);
[[nodiscard]] Mask litByAtLeast(std::span<const algo::ImageView<const std::uint8_t>> lits, int n);
// Keeps a pixel only when no 0 pixel and no out-of-image position lies within Euclidean distance
// radiusPx of it (radius 0: unchanged).
[[nodiscard]] Mask erode(const Mask& mask, int radiusPx);
// Keeps a pixel only when every in-image pixel of its 3×3 neighbourhood has a finite depth d with
// |d − d(p)| ≤ maxRelativeJump·d(p) (removes occlusion edges and the border of missing depth).
[[nodiscard]] Mask smoothOnly(const Mask& mask, algo::ImageView<const float> depth,
                              double maxRelativeJump);

}  // namespace smx::eval
