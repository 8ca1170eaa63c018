#include "smx/eval/depth_eval.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace smx::eval {

namespace {

template <class A, class B>
void requireSameSize(const A& a, const B& b) {
  if (a.width() != b.width() || a.height() != b.height()) {
    throw std::invalid_argument("depth_eval: planes of different sizes");
  }
}

}  // namespace

bool isGrossError(double zM, double zTruthM) {
  return std::abs(zM - zTruthM) > std::max(kGrossAbsoluteM, kGrossRelative * zTruthM);
}

DepthScore scoreDepth(algo::ConstDepthPlane depth, algo::ImageView<const float> truthDepth,
                      algo::ImageView<const std::uint8_t> region,
                      const DepthScoreOptions& options) {
  requireSameSize(depth, truthDepth);
  requireSameSize(depth, region);
  DepthScore s;
  double sumSquares = 0;
  double sum = 0;
  double disparitySquares = 0;
  for (int y = 0; y < depth.height(); ++y) {
    for (int x = 0; x < depth.width(); ++x) {
      const std::uint16_t d = depth(x, y);
      const double truth = truthDepth(x, y);
      const bool surface = std::isfinite(truth);
      s.validTotal += d != 0 ? 1 : 0;
      if (region(x, y) == 0 || !surface) {
        if (d != 0 && !surface) {
          ++s.phantom;
        } else if (d != 0) {
          ++s.validOutside;
          s.grossOutside += isGrossError(d * options.depthUnitM, truth) ? 1 : 0;
        }
        continue;
      }
      ++s.regionPixels;
      if (d == 0) {
        continue;
      }
      ++s.valid;
      const double z = d * options.depthUnitM;
      if (isGrossError(z, truth)) {
        ++s.gross;
        continue;
      }
      ++s.inliers;
      const double errorMm = (z - truth) * 1000.0;
      sum += errorMm;
      sumSquares += errorMm * errorMm;
      s.maxAbsErrorMm = std::max(s.maxAbsErrorMm, std::abs(errorMm));
      const double disparity =
          options.fxPx * options.baselineM * std::abs(z - truth) / (truth * truth);
      disparitySquares += disparity * disparity;
    }
  }
  if (s.regionPixels > 0) {
    s.completeness = static_cast<double>(s.valid) / s.regionPixels;
  }
  if (s.valid > 0) {
    s.grossRate = static_cast<double>(s.gross) / s.valid;
  }
  if (s.inliers > 0) {
    s.rmseMm = std::sqrt(sumSquares / s.inliers);
    s.meanErrorMm = sum / s.inliers;
    s.rmsDisparityPx = std::sqrt(disparitySquares / s.inliers);
  }
  return s;
}

std::vector<float> depthErrorMapMm(algo::ConstDepthPlane depth,
                                   algo::ImageView<const float> truthDepth, double depthUnitM) {
  requireSameSize(depth, truthDepth);
  std::vector<float> map;
  map.reserve(static_cast<std::size_t>(depth.width()) * static_cast<std::size_t>(depth.height()));
  for (int y = 0; y < depth.height(); ++y) {
    for (int x = 0; x < depth.width(); ++x) {
      const std::uint16_t d = depth(x, y);
      const float truth = truthDepth(x, y);
      map.push_back(d != 0 && std::isfinite(truth)
                        ? static_cast<float>((d * depthUnitM - truth) * 1000.0)
                        : std::numeric_limits<float>::quiet_NaN());
    }
  }
  return map;
}

}  // namespace smx::eval
