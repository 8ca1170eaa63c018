#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "smx/algo/stripe_code.hpp"
#include "smx/calib/projector_calibration.hpp"

namespace smx::calib {
namespace {

// Residuals beyond this many robust standard deviations are decoding errors, not noise.
constexpr double kOutlierSigmas = 5.0;
// Huber loss scale, projector px: a boundary is found to a fraction of a camera pixel, a few
// tenths of a projector pixel at most.
constexpr double kHuberPx = 0.5;
// The centre along the stripes' direction is not observed; this weak prior keeps it at nominal.
constexpr double kPriorM = 0.01;

// The fixed part of the model: what the samples do not determine.
struct Fixed {
  double fx = 1.0;  // nominal: the fit scales both focal lengths by one factor
  double fy = 1.0;
  double cx = 0.0;  // nominal: the fit moves the principal point along the encoding axis only
  double cy = 0.0;
  double cosA = 1.0;
  double sinA = 0.0;
  double patternCu = 0.0;  // the pattern's centre, projector px
  double patternCv = 0.0;
  double offsetPx = 0.0;
  double stripePx = 1.0;
  double k3 = 0.0;
};

// Parameters: rotation (angle-axis, world → device), centre (world), [focal scale, principal
// point shift along the encoding axis (px)], [k1 k2 p1 p2].
struct StripeResidual {
  Eigen::Vector3d point;
  double observed;  // stripe coordinate
  const Fixed* fixed;

  template <class T>
  bool operator()(const T* rotation, const T* centre, const T* intrinsics, const T* lens,
                  T* residual) const {
    const T rel[3] = {T(point[0]) - centre[0], T(point[1]) - centre[1], T(point[2]) - centre[2]};
    T dev[3];
    ceres::AngleAxisRotatePoint(rotation, rel, dev);
    const T x = dev[0] / dev[2];
    const T y = dev[1] / dev[2];
    const T r2 = x * x + y * y;
    const T radial = T(1) + lens[0] * r2 + lens[1] * r2 * r2 + T(fixed->k3) * r2 * r2 * r2;
    const T xd = x * radial + T(2) * lens[2] * x * y + lens[3] * (r2 + T(2) * x * x);
    const T yd = y * radial + lens[2] * (r2 + T(2) * y * y) + T(2) * lens[3] * x * y;
    const T u = intrinsics[0] * T(fixed->fx) * xd + T(fixed->cx) + intrinsics[1] * T(fixed->cosA);
    const T v = intrinsics[0] * T(fixed->fy) * yd + T(fixed->cy) + intrinsics[1] * T(fixed->sinA);
    const T along = (u - T(fixed->patternCu)) * T(fixed->cosA) +
                    (v - T(fixed->patternCv)) * T(fixed->sinA) - T(fixed->offsetPx);
    const T predicted = along / T(fixed->stripePx) + T(algo::stripe::kStripes / 2.0);
    residual[0] = (predicted - T(observed)) * T(fixed->stripePx);
    return true;
  }
};

struct CentrePrior {
  Eigen::Vector3d nominal;
  Eigen::Vector3d direction;  // unit, world: the stripes' direction through the centre

  template <class T>
  bool operator()(const T* centre, T* residual) const {
    T along = T(0);
    for (int i = 0; i < 3; ++i) {
      along += (centre[i] - T(nominal[i])) * T(direction[i]);
    }
    residual[0] = along / T(kPriorM);
    return true;
  }
};

struct Params {
  std::array<double, 3> rotation{};
  std::array<double, 3> centre{};
  std::array<double, 2> intrinsics{};
  std::array<double, 4> lens{};
};

Eigen::Matrix3d rowMajor(const std::array<double, 9>& m) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.data());
}

double residualOf(const StripeSample& s, const Params& p, const Fixed& f) {
  double r = 0.0;
  StripeResidual{s.point, s.stripe, &f}(p.rotation.data(), p.centre.data(), p.intrinsics.data(),
                                        p.lens.data(), &r);
  return r;
}

void solve(const std::vector<const StripeSample*>& used, const Fixed& fixed, Params& params,
           const CentrePrior& prior) {
  ceres::Problem problem;
  for (const StripeSample* s : used) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<StripeResidual, 1, 3, 3, 2, 4>(
                                 new StripeResidual{s->point, s->stripe, &fixed}),
                             new ceres::HuberLoss(kHuberPx), params.rotation.data(),
                             params.centre.data(), params.intrinsics.data(), params.lens.data());
  }
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<CentrePrior, 1, 3>(new CentrePrior(prior)), nullptr,
      params.centre.data());
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

std::expected<ProjectorFit, std::string> fitProjector(const algo::Projector& nominal,
                                                      const std::vector<StripeSample>& samples,
                                                      const CaptureSet& set) {
  // Fewer poses than this and the focal length is not told from the distance.
  constexpr std::size_t kMinSamples = 1000;
  if (samples.size() < kMinSamples) {
    return std::unexpected(nominal.id + ": only " + std::to_string(samples.size()) +
                           " stripe samples decoded on the target; is the projector on in its "
                           "frames and aimed at the target?");
  }
  const double a = nominal.pattern.angleDeg * std::numbers::pi / 180.0;
  const Fixed fixed{.fx = nominal.fx(),
                    .fy = nominal.fy(),
                    .cx = nominal.cx(),
                    .cy = nominal.cy(),
                    .cosA = std::cos(a),
                    .sinA = std::sin(a),
                    .patternCu = (nominal.width - 1) / 2.0,
                    .patternCv = (nominal.height - 1) / 2.0,
                    .offsetPx = nominal.pattern.offsetPx,
                    .stripePx = nominal.pattern.stripePx,
                    .k3 = nominal.dist[4]};
  const Eigen::Matrix3d R0 = rowMajor(nominal.R);
  const Eigen::Vector3d t0(nominal.t[0], nominal.t[1], nominal.t[2]);
  const Eigen::Vector3d c0 = -R0.transpose() * t0;
  Params params;
  const Eigen::AngleAxisd aa(R0);
  const Eigen::Vector3d rv = aa.axis() * aa.angle();
  params.rotation = {rv[0], rv[1], rv[2]};
  params.centre = {c0[0], c0[1], c0[2]};
  params.intrinsics = {1.0, 0.0};
  params.lens = {nominal.dist[0], nominal.dist[1], nominal.dist[2], nominal.dist[3]};
  const Eigen::Vector3d alongStripes =
      R0.transpose() * Eigen::Vector3d(-std::sin(a), std::cos(a), 0.0);
  const CentrePrior prior{c0, alongStripes.normalized()};

  std::vector<const StripeSample*> used;
  used.reserve(samples.size());
  for (const StripeSample& s : samples) {
    used.push_back(&s);
  }
  // Solve, drop what lies beyond kOutlierSigmas robust deviations, solve again.
  for (int round = 0; round < 3; ++round) {
    solve(used, fixed, params, prior);
    std::vector<double> abs;
    abs.reserve(used.size());
    for (const StripeSample* s : used) {
      abs.push_back(std::abs(residualOf(*s, params, fixed)));
    }
    std::vector<double> sorted = abs;
    std::nth_element(sorted.begin(),
                     sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double sigma = 1.4826 * sorted[sorted.size() / 2];
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
  fit.projector = nominal;
  Eigen::Vector3d rvec(params.rotation[0], params.rotation[1], params.rotation[2]);
  const double angle = rvec.norm();
  const Eigen::Matrix3d R = angle > 0 ? Eigen::AngleAxisd(angle, rvec / angle).toRotationMatrix()
                                      : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d c(params.centre[0], params.centre[1], params.centre[2]);
  const Eigen::Vector3d t = -R * c;
  for (int i = 0; i < 9; ++i) {
    fit.projector.R[static_cast<std::size_t>(i)] = R(i / 3, i % 3);
  }
  fit.projector.t = {t[0], t[1], t[2]};
  const double scale = params.intrinsics[0];
  const double shift = params.intrinsics[1];
  fit.projector.K = {scale * fixed.fx,
                     0,
                     fixed.cx + shift * fixed.cosA,
                     0,
                     scale * fixed.fy,
                     fixed.cy + shift * fixed.sinA,
                     0,
                     0,
                     1};
  fit.projector.dist = {params.lens[0], params.lens[1], params.lens[2], params.lens[3], fixed.k3};
  fit.fixedAtNominal = {"fy/fx (one focal scale fitted)", "the principal point along the stripes",
                        "the centre along the stripes' direction", "k3"};

  // Residuals per pose, over the samples kept; outliers are those dropped.
  fit.poses.resize(set.poses.size());
  for (std::size_t p = 0; p < set.poses.size(); ++p) {
    fit.poses[p].pose = set.poses[p].name;
  }
  for (const StripeSample& s : samples) {
    fit.poses[s.pose].outliers++;
  }
  double sumPx = 0.0;
  double sumMm = 0.0;
  std::vector<double> posePx(set.poses.size(), 0.0);
  std::vector<double> poseMm(set.poses.size(), 0.0);
  for (const StripeSample* s : used) {
    const double r = residualOf(*s, params, fixed);
    const double mm = r / (scale * fixed.fx) * (s->point - c).norm() * 1000.0;
    sumPx += r * r;
    sumMm += mm * mm;
    posePx[s->pose] += r * r;
    poseMm[s->pose] += mm * mm;
    fit.poses[s->pose].samples++;
    fit.poses[s->pose].outliers--;
  }
  for (std::size_t p = 0; p < set.poses.size(); ++p) {
    const int n = fit.poses[p].samples;
    if (n > 0) {
      fit.poses[p].rmsPx = std::sqrt(posePx[p] / n);
      fit.poses[p].rmsMm = std::sqrt(poseMm[p] / n);
    }
  }
  fit.samples = static_cast<int>(used.size());
  fit.outliers = static_cast<int>(samples.size() - used.size());
  fit.rmsPx = std::sqrt(sumPx / static_cast<double>(used.size()));
  fit.rmsMm = std::sqrt(sumMm / static_cast<double>(used.size()));
  return fit;
}

}  // namespace smx::calib
