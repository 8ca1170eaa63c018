#include "smx/health/disagreement.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "smx/health/chi_square_mix.hpp"

namespace smx::health {

namespace {

// The robust scale of a normal distribution from its median absolute deviation.
constexpr double kMadToSigma = 1.4826;
constexpr double kInlierSigmas = 3.0;
constexpr int kFitRounds = 5;
// A floor for σ so that perfectly equal depths (quantised to one depth unit) keep their blocks.
constexpr double kMinSigmaMm = 0.01;

double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::ranges::nth_element(v, mid);
  if (v.size() % 2 == 1) {
    return *mid;
  }
  return 0.5 * (*mid + *std::max_element(v.begin(), mid));
}

std::vector<Block> blockMedians(const DisagreementField& field, const Thresholds& t, int& pixels) {
  std::vector<Block> blocks;
  const int bw = (field.width + t.blockPx - 1) / t.blockPx;
  const int bh = (field.height + t.blockPx - 1) / t.blockPx;
  std::vector<double> values;
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      values.clear();
      double sx = 0;
      double sy = 0;
      for (int y = by * t.blockPx; y < std::min(field.height, (by + 1) * t.blockPx); ++y) {
        for (int x = bx * t.blockPx; x < std::min(field.width, (bx + 1) * t.blockPx); ++x) {
          const double d =
              field.mm[static_cast<std::size_t>(y) * static_cast<std::size_t>(field.width) +
                       static_cast<std::size_t>(x)];
          if (!std::isnan(d)) {
            values.push_back(d);
            sx += x;
            sy += y;
          }
        }
      }
      pixels += static_cast<int>(values.size());
      if (static_cast<int>(values.size()) < t.minBlockPixels) {
        continue;
      }
      const auto n = static_cast<double>(values.size());
      blocks.push_back({bx, by, (sx / n - 0.5 * (field.width - 1)) / (0.5 * field.width),
                        (sy / n - 0.5 * (field.height - 1)) / (0.5 * field.height),
                        median(values)});
    }
  }
  return blocks;
}

// Least squares a + b·x + c·y over the blocks marked in `use`; false if singular.
bool fitPlane(const std::vector<Block>& blocks, const std::vector<bool>& use,
              std::array<double, 3>& p) {
  std::array<std::array<double, 4>, 3> m{};
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    if (!use[i]) {
      continue;
    }
    const std::array<double, 3> row{1.0, blocks[i].x, blocks[i].y};
    for (std::size_t r = 0; r < 3; ++r) {
      for (std::size_t c = 0; c < 3; ++c) {
        m[r][c] += row[r] * row[c];
      }
      m[r][3] += row[r] * blocks[i].mm;
    }
  }
  // Gauss–Jordan with partial pivoting on the 3×3 normal equations.
  for (std::size_t c = 0; c < 3; ++c) {
    std::size_t pivot = c;
    for (std::size_t r = c + 1; r < 3; ++r) {
      if (std::abs(m[r][c]) > std::abs(m[pivot][c])) {
        pivot = r;
      }
    }
    if (std::abs(m[pivot][c]) < 1e-9) {
      return false;
    }
    std::swap(m[c], m[pivot]);
    for (std::size_t r = 0; r < 3; ++r) {
      if (r != c) {
        const double f = m[r][c] / m[c][c];
        for (std::size_t k = c; k < 4; ++k) {
          m[r][k] -= f * m[c][k];
        }
      }
    }
  }
  for (std::size_t r = 0; r < 3; ++r) {
    p[r] = m[r][3] / m[r][r];
  }
  return true;
}

}  // namespace

Disagreement fitDisagreement(const DisagreementField& field, const Thresholds& thresholds) {
  Disagreement d;
  const std::vector<Block> blocks = blockMedians(field, thresholds, d.pixels);
  d.blocks = static_cast<int>(blocks.size());
  if (d.blocks < thresholds.minBlocks) {
    return d;
  }
  std::vector<double> values;
  values.reserve(blocks.size());
  for (const Block& b : blocks) {
    values.push_back(b.mm);
  }
  std::array<double, 3> plane{median(values), 0.0, 0.0};
  std::vector<bool> use(blocks.size(), true);
  double sigma = 0;
  for (int round = 0; round < kFitRounds; ++round) {
    std::vector<double> absResiduals;
    absResiduals.reserve(blocks.size());
    for (const Block& b : blocks) {
      absResiduals.push_back(std::abs(b.mm - plane[0] - plane[1] * b.x - plane[2] * b.y));
    }
    sigma = std::max(kMinSigmaMm, kMadToSigma * median(absResiduals));
    for (std::size_t i = 0; i < blocks.size(); ++i) {
      use[i] = absResiduals[i] <= kInlierSigmas * sigma;
    }
    if (std::ranges::count(use, true) < thresholds.minBlocks || !fitPlane(blocks, use, plane)) {
      return d;
    }
  }
  // The plane is judged over the whole image, not only over the compared blocks: a drift
  // disturbs the rig's whole field of view, and a small object would otherwise hide a trend. With
  // x, y uniform over [−1, 1]², the plane's mean square over the image is pᵀ·G·p, G = diag(1,
  // 1/3, 1/3). Its noise: the fitted p has covariance σ²·A⁻¹ (A = Σ rᵀr over the inlier blocks,
  // r = (1, x, y)), so pᵀ·G·p under pure noise is σ² times a sum of χ²₁ weighted by the
  // eigenvalues of G^½·A⁻¹·G^½. Blocks over the whole image give A ≈ n·G: σ²·χ²₃/n.
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    if (use[i]) {
      d.inliers.push_back(blocks[i]);
      const Eigen::Vector3d r(1.0, blocks[i].x, blocks[i].y);
      a += r * r.transpose();
    }
  }
  const Eigen::Vector3d gRoot(1.0, 1.0 / std::sqrt(3.0), 1.0 / std::sqrt(3.0));
  const Eigen::Vector3d p(plane[0], plane[1], plane[2]);
  const Eigen::Matrix3d spread = gRoot.asDiagonal() * a.inverse() * gRoot.asDiagonal();
  const Eigen::Vector3d weights =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(spread, Eigen::EigenvaluesOnly).eigenvalues();
  d.offsetMm = plane[0];
  d.slopeXMm = plane[1];
  d.slopeYMm = plane[2];
  d.sigmaMm = sigma;
  d.systematicMm = gRoot.cwiseProduct(p).norm();
  d.noiseMm = sigma * std::sqrt(weightedChiSquareQuantile({weights[0], weights[1], weights[2]},
                                                          thresholds.falseAlarm));
  d.thresholdMm = d.noiseMm + thresholds.toleranceMm;
  d.enough = true;
  d.disagrees = d.systematicMm > d.thresholdMm;
  return d;
}

}  // namespace smx::health
