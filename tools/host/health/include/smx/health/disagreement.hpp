#pragma once

#include <vector>

// The systematic part of a disagreement between two depth measurements of the same surface
// (docs/health-check.md). The per-pixel differences are first reduced to block medians (the
// pixels of one block share their stripe boundaries, so their noise is not independent, and a
// median lets neither silhouettes nor a few wrong codes decide); then a plane a + b·x + c·y over
// the image is fitted to the block medians, robustly (blocks beyond 3 robust standard deviations,
// 1.4826·MAD, take no part). Host code.
namespace smx::health {

struct Thresholds {
  int blockPx = 8;          // block side, camera pixels
  int minBlockPixels = 16;  // compared pixels a block needs for its median
  int minBlocks = 40;       // compared blocks a comparison needs ("not enough overlap" below)
  // The probability that noise alone exceeds the noise bound (the plane's mean square over the
  // image beyond its 1 − falseAlarm quantile).
  double falseAlarm = 1e-4;
  // The systematic disagreement accepted beyond the noise (mm at the reference distance): half
  // the smallest that a 1 mm or 0.2° projector drift causes on the example rigs and scenes
  // (1.43 mm), above the largest that decoding leaves between correct calibrations (0.42 mm
  // beyond the noise; docs/health-check.md).
  double toleranceMm = 0.7;
};

// Disagreements are compared as they would be at one reference distance. A projector that turns
// moves its stripe planes by an angle, and the depth error that causes grows with z²; scaled by
// (reference / z)², a turn disagrees alike on a near and a far scene, and one tolerance holds
// for both. (A shift's error grows only with z: near scenes show it larger still.)
constexpr double kReferenceDistanceM = 1.0;

[[nodiscard]] inline double atReferenceDistance(double mm, double depthM) {
  const double scale = kReferenceDistanceM / depthM;
  return mm * scale * scale;
}

// A disagreement image: per pixel of one camera image, mm at the reference distance, NaN where
// the two measurements do not overlap.
struct DisagreementField {
  int width = 0;
  int height = 0;
  std::vector<double> mm;
};

struct Block {
  int bx = 0;  // block column and row
  int by = 0;
  double x = 0;  // block centre, normalised to [−1, 1] over the image width / height
  double y = 0;
  double mm = 0;  // median disagreement of the block
};

struct Disagreement {
  int pixels = 0;  // compared pixels
  int blocks = 0;  // blocks with a median
  std::vector<Block> inliers;
  // The plane, mm: offset at the image centre, and change from the centre to the right / bottom
  // edge.
  double offsetMm = 0;
  double slopeXMm = 0;
  double slopeYMm = 0;
  double sigmaMm = 0;       // robust scatter of the block medians about the plane
  double systematicMm = 0;  // RMS of the plane over the inlier blocks: what is judged
  double noiseMm = 0;       // σ·√(χ²/n): what noise alone can give
  double thresholdMm = 0;   // noiseMm + toleranceMm
  bool enough = false;      // at least minBlocks blocks
  bool disagrees = false;   // enough and systematicMm > thresholdMm
};

[[nodiscard]] Disagreement fitDisagreement(const DisagreementField& field,
                                           const Thresholds& thresholds);

}  // namespace smx::health
