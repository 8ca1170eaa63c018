#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/eval/boundary_eval.hpp"
#include "smx/eval/depth_eval.hpp"
#include "smx/eval/realism_attribution.hpp"
#include "smx/eval/realism_case.hpp"
#include "smx/eval/sim_frame.hpp"
#include "smx/eval/wrong_depth.hpp"

// The realism suite's scoring (`stripemux eval --only realism`, docs/results.md): each camera of
// a generated case (realism_case.hpp) rendered, decoded by the firmware's camera pipeline (its
// directions predicted at the case's working distance) and scored against the truth. Host code;
// throws std::runtime_error when a render or a pipeline that was accepted fails.
//
// Regions (all from the truth, as depth_eval.hpp scores them):
//   lit         lit by ≥ 1 projector;  smooth: litRegion's smooth interior;
//   lit by 2/3  exactly 2 / 3 projectors, smooth;
//   resolvable  smooth pixels where every projector that lights them has stripes ≥ 2.5 px wide
//               in the camera (1 / |∇s| of the truth stripe plane, stripeGradient), and ∇s is
//               defined for each of them;
//   outside band  lit pixels farther than 2 px (Euclidean) from every depth discontinuity of the
//               truth: a pixel whose 4-neighbour has a finite depth while it has none (or the
//               reverse), or a depth more than 2 % apart.
namespace smx::eval {

inline constexpr double kResolvableStripePx = 2.5;
inline constexpr int kDiscontinuityBandPx = 2;

struct RealismRun {
  int caseIndex = 0;
  int camera = 0;
  std::string summary;  // the case's (devices, distance, objects, background)
  std::string rig;      // per projector: baseline to this camera, axis, designed stripe width
  int projectors = 0;
  double workingDistanceM = 0;
  bool refused = false;
  std::string reason;  // prepareCameraPipeline's error when refused

  DepthScore lit;
  DepthScore smooth;
  DepthScore lit2;
  DepthScore lit3;
  DepthScore resolvable;
  DepthScore outsideBand;
  std::vector<double> medianStripePx;  // per projector, over the pixels it lights (truth)
  Attribution attribution;             // what stops the targets (realism_attribution.hpp)
  WrongDepth wrongDepth;               // the gross pixels outside the band (wrong_depth.hpp)

  // Kept for the worst cases only (keepWorstImages): the camera image and merged − truth, mm.
  OwnedPlane<algo::Rgb8> image;
  std::vector<float> errorMm;
};

// Every camera of the case; `seed` is the renders' noise seed.
[[nodiscard]] std::vector<RealismRun> runRealismCase(const RealismCase& c, std::uint64_t seed,
                                                     int supersampling);

// Regions (exposed for the tests).
[[nodiscard]] Mask discontinuityBand(algo::ImageView<const float> depth, int radiusPx);
[[nodiscard]] Mask resolvableRegion(const SimFrame& frame);
// Median of 1 / |∇s| over the pixels where projector p's ∇s is defined; 0 when none.
[[nodiscard]] double medianStripeWidthPx(const SimFrame& frame, int projector);

// Pixel-weighted sum of scores: counts add up, completeness and gross rate are ratios of the
// sums, RMSE figures are root means of the squares over all inliers.
[[nodiscard]] DepthScore sumScores(std::span<const DepthScore> scores);

// Rank by gross-error rate outside the band (refused runs last); images are dropped from all
// but the first `keep` of that order.
void keepWorstImages(std::vector<RealismRun>& runs, int keep);
[[nodiscard]] std::vector<const RealismRun*> worstRuns(const std::vector<RealismRun>& runs,
                                                       int count);

}  // namespace smx::eval
