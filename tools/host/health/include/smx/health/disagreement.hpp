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
  // χ² with 3 degrees of freedom (the plane) at a false-alarm probability of 1e-4: pure noise
  // gives a plane whose RMS over n blocks stays below σ·√(χ²/n).
  double chiSquare = 21.1;
  // The systematic disagreement accepted beyond the noise: half the smallest that a 1 mm or 0.2°
  // projector drift causes on the example rigs (about 1 mm; docs/health.md), twice the
  // largest that decoding leaves between correct calibrations (about 0.3 mm).
  double toleranceMm = 0.5;
};

// A disagreement image in metres-free form: per pixel of one camera image, mm, NaN where the two
// measurements do not overlap.
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
