#pragma once

#include <cstdint>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/algo/range_image.hpp"

// Evaluation (stripemux eval, accuracy tests): scores a range image (uint16 z in the camera frame
// in depth units, 0 = no data) against the simulator's truth depth (float z in metres, NaN where
// the ray hits nothing). Host code, double precision; throws std::invalid_argument on planes of
// different sizes.
//
// Definitions (z = depth·unit, z_gt = truth, both metres):
//   region pixels   pixels with region ≠ 0 and a finite z_gt;
//   valid           region pixels with depth ≠ 0;       completeness = valid / region pixels;
//   gross           valid with |z − z_gt| > max(5 mm, 1 % of z_gt);  grossRate = gross / valid;
//   of the valid that are not gross ("inliers"): rmseMm, meanErrorMm (z − z_gt, signed),
//   maxAbsErrorMm, and rmsDisparityPx = RMS of fx·b·|z − z_gt| / z_gt² (the disparity error in
//   camera pixels that the depth error amounts to for a camera–projector baseline b);
//   outside the region: phantom = depth ≠ 0 where z_gt is NaN; validOutside = depth ≠ 0 where
//   z_gt is finite and region = 0, grossOutside = those of them that are gross;
//   validTotal = depth ≠ 0 anywhere.
// Ratios of empty sets are 0 and statistics of an empty set are 0: check the counts.
namespace smx::eval {

inline constexpr double kGrossAbsoluteM = 0.005;
inline constexpr double kGrossRelative = 0.01;

// True when z is a gross error against z_gt (definition above).
[[nodiscard]] bool isGrossError(double zM, double zTruthM);

struct DepthScoreOptions {
  double depthUnitM = algo::kDefaultDepthUnitM;
  double fxPx = 0;       // camera focal length, pixels (for rmsDisparityPx)
  double baselineM = 0;  // camera–projector baseline, metres (for rmsDisparityPx)
};

struct DepthScore {
  int regionPixels = 0;
  int valid = 0;
  int gross = 0;
  int inliers = 0;
  double completeness = 0;
  double grossRate = 0;
  double rmseMm = 0;
  double meanErrorMm = 0;
  double maxAbsErrorMm = 0;
  double rmsDisparityPx = 0;
  int phantom = 0;
  int validOutside = 0;
  int grossOutside = 0;
  int validTotal = 0;
};

[[nodiscard]] DepthScore scoreDepth(algo::ConstDepthPlane depth,
                                    algo::ImageView<const float> truthDepth,
                                    algo::ImageView<const std::uint8_t> region,
                                    const DepthScoreOptions& options = {});

// Signed error z − z_gt in mm per pixel (row-major), NaN where depth is 0 or z_gt is NaN.
[[nodiscard]] std::vector<float> depthErrorMapMm(algo::ConstDepthPlane depth,
                                                 algo::ImageView<const float> truthDepth,
                                                 double depthUnitM = algo::kDefaultDepthUnitM);

}  // namespace smx::eval
