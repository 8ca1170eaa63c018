#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "projector_model.hpp"
#include "smx/algo/lens.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/calib/projector_calibration.hpp"

namespace smx::calib {
namespace {

using detail::CentrePrior;
using detail::ProjectorConstants;
using detail::ProjectorParams;

// Residuals beyond this many robust standard deviations are decoding errors, not noise.
constexpr double kOutlierSigmas = 5.0;
// Huber loss scale, projector px: a boundary is found to a fraction of a camera pixel, a few
// tenths of a projector pixel at most.
constexpr double kHuberPx = 0.5;
// Fewer samples and a dozen parameters are not fitted with any margin.
constexpr std::size_t kMinSamples = 1000;

struct StripeResidual {
  const StripeSample* sample;
  const ProjectorConstants* constants;

  template <class T>
  bool operator()(const T* rotation, const T* centre, const T* intrinsics, const T* lens,
                  T* residual) const {
    const T world[3] = {static_cast<T>(sample->point[0]), static_cast<T>(sample->point[1]),
                        static_cast<T>(sample->point[2])};
    const T s = detail::stripeAt(*constants, rotation, centre, intrinsics, lens, world);
    residual[0] = (s - static_cast<T>(sample->stripe)) * static_cast<T>(constants->stripePx);
    return true;
  }
};

void solve(const std::vector<const StripeSample*>& used, const ProjectorConstants& constants,
           ProjectorParams& params, const CentrePrior& prior, const detail::LensPrior& lens) {
  ceres::Problem problem;
  for (const StripeSample* s : used) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<StripeResidual, 1, 3, 3, 2, 4>(
                                 new StripeResidual{s, &constants}),
                             new ceres::HuberLoss(kHuberPx), params.rotation.data(),
                             params.centre.data(), params.intrinsics.data(), params.lens.data());
  }
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<CentrePrior, 1, 3>(new CentrePrior(prior)), nullptr,
      params.centre.data());
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<detail::LensPrior, 4, 4>(new detail::LensPrior(lens)),
      nullptr, params.lens.data());
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  options.num_threads = 2;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
}

}  // namespace

double stripeResidualPx(const algo::Projector& projector, const StripeSample& sample) {
  const auto q =
      algo::lens::project(projector, {sample.point[0], sample.point[1], sample.point[2]});
  if (!q) {
    return std::numeric_limits<double>::infinity();
  }
  const double s =
      algo::stripeCoordinate(projector.pattern, projector.width, projector.height, q->x, q->y);
  return (s - sample.stripe) * projector.pattern.stripePx;
}

void measureResiduals(ProjectorFit& fit, const std::vector<StripeSample>& all,
                      const CaptureSet& set) {
  fit.poses.assign(set.poses.size(), {});
  for (std::size_t p = 0; p < set.poses.size(); ++p) {
    fit.poses[p].pose = set.poses[p].name;
  }
  for (const StripeSample& s : all) {
    fit.poses[s.pose].outliers++;
  }
  const auto c = algo::lens::centre(fit.projector);
  const Eigen::Vector3d centre(c[0], c[1], c[2]);
  std::vector<double> px(set.poses.size(), 0.0);
  std::vector<double> mm(set.poses.size(), 0.0);
  double sumPx = 0.0;
  double sumMm = 0.0;
  for (const StripeSample& s : fit.inliers) {
    const double r = stripeResidualPx(fit.projector, s);
    // Across the boundary surface at the sample's range: a projector pixel subtends 1/fx rad.
    const double d = r / fit.projector.fx() * (s.point - centre).norm() * 1000.0;
    px[s.pose] += r * r;
    mm[s.pose] += d * d;
    sumPx += r * r;
    sumMm += d * d;
    fit.poses[s.pose].samples++;
    fit.poses[s.pose].outliers--;
  }
  for (std::size_t p = 0; p < set.poses.size(); ++p) {
    const int n = fit.poses[p].samples;
    fit.poses[p].rmsPx = n > 0 ? std::sqrt(px[p] / n) : 0.0;
    fit.poses[p].rmsMm = n > 0 ? std::sqrt(mm[p] / n) : 0.0;
  }
  const auto n = static_cast<double>(std::max<std::size_t>(fit.inliers.size(), 1));
  fit.samples = static_cast<int>(fit.inliers.size());
  fit.outliers = static_cast<int>(all.size() - fit.inliers.size());
  fit.rmsPx = std::sqrt(sumPx / n);
  fit.rmsMm = std::sqrt(sumMm / n);
}

std::expected<ProjectorFit, std::string> fitProjector(const algo::Projector& nominal,
                                                      const std::vector<StripeSample>& samples,
                                                      const CaptureSet& set) {
  if (samples.size() < kMinSamples) {
    return std::unexpected(nominal.id + ": only " + std::to_string(samples.size()) +
                           " stripe samples decoded on the target; is the projector on in its "
                           "frames and aimed at the target?");
  }
  const ProjectorConstants constants(nominal);
  ProjectorParams params = detail::paramsOf(nominal);
  const CentrePrior prior(nominal, constants);
  // The data residuals here are in projector px: the prior in the same unit, at the scatter a
  // decoded boundary has (kHuberPx is a few of them).
  const detail::LensPrior lensPrior{
      .nominal = {nominal.dist[0], nominal.dist[1], nominal.dist[2], nominal.dist[3]},
      .scale = kHuberPx / 2};

  std::vector<const StripeSample*> used;
  used.reserve(samples.size());
  for (const StripeSample& s : samples) {
    used.push_back(&s);
  }
  // Solve, drop what lies beyond kOutlierSigmas robust deviations, solve again.
  for (int round = 0; round < 3; ++round) {
    solve(used, constants, params, prior, lensPrior);
    const algo::Projector current = detail::projectorOf(nominal, constants, params);
    std::vector<double> abs;
    abs.reserve(used.size());
    for (const StripeSample* s : used) {
      abs.push_back(std::abs(stripeResidualPx(current, *s)));
    }
    std::vector<double> sorted = abs;
    const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
    std::nth_element(sorted.begin(), mid, sorted.end());
    const double sigma = 1.4826 * *mid;
    std::vector<const StripeSample*> kept;
    for (std::size_t i = 0; i < used.size(); ++i) {
      if (abs[i] <= kOutlierSigmas * sigma) {
        kept.push_back(used[i]);
      }
    }
    const bool stable = kept.size() == used.size();
    used = std::move(kept);
    if (stable) {
      break;
    }
  }

  ProjectorFit fit;
  fit.projector = detail::projectorOf(nominal, constants, params);
  fit.fixedAtNominal = {"fy/fx (one focal scale fitted)", "the principal point along the stripes",
                        "the centre along the stripes' direction", "k3"};
  for (const StripeSample* s : used) {
    fit.inliers.push_back(*s);
  }
  measureResiduals(fit, samples, set);
  return fit;
}

}  // namespace smx::calib
