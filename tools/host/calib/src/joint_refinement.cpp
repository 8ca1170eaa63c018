#include "smx/calib/joint_refinement.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "projector_model.hpp"
#include "smx/algo/lens.hpp"

namespace smx::calib {
namespace {

using detail::CentrePrior;
using detail::ProjectorConstants;
using detail::ProjectorParams;

// Neighbouring stripe samples are interpolated from the same pair of decoded boundaries, so they
// are not independent: each counts as this share of a measurement of its own.
constexpr double kStripeSampleShare = 0.25;
// Robust loss scales, in standard deviations of each kind.
constexpr double kHuberSigmas = 3.0;
// Scatter floors: below these a fit's RMS says more about luck than about the measurement.
constexpr double kMinCornerSigmaPx = 0.02;
constexpr double kMinStripeSigmaPx = 0.02;
constexpr int kUndistortIterations = 12;

struct CameraParams {
  std::array<double, 4> intrinsics{};  // fx fy cx cy
  std::array<double, 5> lens{};        // k1 k2 p1 p2 k3
  std::array<double, 3> rotation{};    // world → camera, angle-axis
  std::array<double, 3> t{};
};

struct PoseParams {
  std::array<double, 3> rotation{};  // target → world, angle-axis
  std::array<double, 3> t{};
};

std::array<double, 3> angleAxis(const Eigen::Matrix3d& rot) {
  const Eigen::AngleAxisd aa(rot);
  const Eigen::Vector3d v = aa.axis() * aa.angle();
  return {v[0], v[1], v[2]};
}

Eigen::Matrix3d matrix(const std::array<double, 3>& aa) {
  const Eigen::Vector3d v(aa[0], aa[1], aa[2]);
  const double angle = v.norm();
  return angle > 0 ? Eigen::AngleAxisd(angle, v / angle).toRotationMatrix()
                   : Eigen::Matrix3d::Identity();
}

template <class T>
void distort(const T* lens, const T& x, const T& y, T& xd, T& yd) {
  const T r2 = x * x + y * y;
  const T radial = static_cast<T>(1) + lens[0] * r2 + lens[1] * r2 * r2 + lens[4] * r2 * r2 * r2;
  xd =
      x * radial + static_cast<T>(2) * lens[2] * x * y + lens[3] * (r2 + static_cast<T>(2) * x * x);
  yd =
      y * radial + lens[2] * (r2 + static_cast<T>(2) * y * y) + static_cast<T>(2) * lens[3] * x * y;
}

struct CornerResidual {
  std::array<double, 2> target;  // the corner in the target frame
  std::array<double, 2> image;
  double sigma;

  template <class T>
  bool operator()(const T* intrinsics, const T* lens, const T* camRotation, const T* camT,
                  const T* poseRotation, const T* poseT, T* residual) const {
    const T local[3] = {static_cast<T>(target[0]), static_cast<T>(target[1]), static_cast<T>(0)};
    T world[3];
    ceres::AngleAxisRotatePoint(poseRotation, local, world);
    for (int i = 0; i < 3; ++i) {
      world[i] += poseT[i];
    }
    T cam[3];
    ceres::AngleAxisRotatePoint(camRotation, world, cam);
    for (int i = 0; i < 3; ++i) {
      cam[i] += camT[i];
    }
    T xd;
    T yd;
    distort(lens, cam[0] / cam[2], cam[1] / cam[2], xd, yd);
    residual[0] =
        (intrinsics[0] * xd + intrinsics[2] - static_cast<T>(image[0])) / static_cast<T>(sigma);
    residual[1] =
        (intrinsics[1] * yd + intrinsics[3] - static_cast<T>(image[1])) / static_cast<T>(sigma);
    return true;
  }
};

struct StripeResidual {
  const StripeSample* sample;
  const ProjectorConstants* constants;
  double sigma;

  template <class T>
  bool operator()(const T* intrinsics, const T* lens, const T* camRotation, const T* camT,
                  const T* poseRotation, const T* poseT, const T* rotation, const T* centre,
                  const T* projIntrinsics, const T* projLens, T* residual) const {
    // The pixel's ray: undistorted by fixed-point iteration, as OpenCV's undistortPoints does.
    const T xd = (static_cast<T>(sample->x) - intrinsics[2]) / intrinsics[0];
    const T yd = (static_cast<T>(sample->y) - intrinsics[3]) / intrinsics[1];
    T x = xd;
    T y = yd;
    for (int i = 0; i < kUndistortIterations; ++i) {
      const T r2 = x * x + y * y;
      const T radial =
          static_cast<T>(1) + lens[0] * r2 + lens[1] * r2 * r2 + lens[4] * r2 * r2 * r2;
      const T dx = static_cast<T>(2) * lens[2] * x * y + lens[3] * (r2 + static_cast<T>(2) * x * x);
      const T dy = lens[2] * (r2 + static_cast<T>(2) * y * y) + static_cast<T>(2) * lens[3] * x * y;
      x = (xd - dx) / radial;
      y = (yd - dy) / radial;
    }
    // Camera → world: the inverse rotation about the camera centre −Rᵀt.
    const T back[3] = {-camRotation[0], -camRotation[1], -camRotation[2]};
    const T dirCam[3] = {x, y, static_cast<T>(1)};
    const T negT[3] = {-camT[0], -camT[1], -camT[2]};
    T dir[3];
    T origin[3];
    ceres::AngleAxisRotatePoint(back, dirCam, dir);
    ceres::AngleAxisRotatePoint(back, negT, origin);
    // The target's plane: normal = R·ez through t.
    const T ez[3] = {static_cast<T>(0), static_cast<T>(0), static_cast<T>(1)};
    T normal[3];
    ceres::AngleAxisRotatePoint(poseRotation, ez, normal);
    T num = static_cast<T>(0);
    T den = static_cast<T>(0);
    for (int i = 0; i < 3; ++i) {
      num += normal[i] * (poseT[i] - origin[i]);
      den += normal[i] * dir[i];
    }
    const T lambda = num / den;
    const T world[3] = {origin[0] + lambda * dir[0], origin[1] + lambda * dir[1],
                        origin[2] + lambda * dir[2]};
    const T s = detail::stripeAt(*constants, rotation, centre, projIntrinsics, projLens, world);
    residual[0] = (s - static_cast<T>(sample->stripe)) * static_cast<T>(constants->stripePx) /
                  static_cast<T>(sigma);
    return true;
  }
};

double rms(const std::vector<double>& values) {
  double sum = 0.0;
  for (const double v : values) {
    sum += v * v;
  }
  return values.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(values.size()));
}

// The solution's covariance, (JᵀJ)⁻¹ over the free parameters in their tangent spaces, from the
// residuals' Jacobian at the solution. Ceres's own Covariance factors the whole Jacobian, which
// for a hundred thousand stripe samples costs far more than the solve; JᵀJ is a few hundred wide.
struct Covariance {
  std::vector<double*> blocks;
  std::vector<int> offsets;  // each block's first column
  Eigen::MatrixXd matrix;

  [[nodiscard]] int offsetOf(const double* block) const {
    const auto at = std::ranges::find(blocks, block);
    return at == blocks.end() ? -1 : offsets[static_cast<std::size_t>(at - blocks.begin())];
  }
};

std::expected<Covariance, std::string> solutionCovariance(ceres::Problem& problem) {
  Covariance out;
  std::vector<double*> all;
  problem.GetParameterBlocks(&all);
  int columns = 0;
  for (double* block : all) {
    if (!problem.IsParameterBlockConstant(block)) {
      out.blocks.push_back(block);
      out.offsets.push_back(columns);
      columns += problem.ParameterBlockTangentSize(block);
    }
  }
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = out.blocks;
  options.num_threads = 2;
  ceres::CRSMatrix jacobian;
  if (!problem.Evaluate(options, nullptr, nullptr, nullptr, &jacobian)) {
    return std::unexpected(std::string("the joint refinement's Jacobian could not be evaluated"));
  }
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(columns, columns);
  for (std::size_t r = 0; r + 1 < jacobian.rows.size(); ++r) {
    const auto begin = static_cast<std::size_t>(jacobian.rows[r]);
    const auto end = static_cast<std::size_t>(jacobian.rows[r + 1]);
    for (std::size_t a = begin; a < end; ++a) {
      for (std::size_t b = begin; b < end; ++b) {
        normal(jacobian.cols[a], jacobian.cols[b]) += jacobian.values[a] * jacobian.values[b];
      }
    }
  }
  // The pseudo-inverse: a direction the data leave flat gets no variance rather than infinity.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(normal);
  if (eigen.info() != Eigen::Success) {
    return std::unexpected(std::string("the joint refinement's covariance could not be computed"));
  }
  const Eigen::VectorXd& values = eigen.eigenvalues();
  const double floor = values.maxCoeff() * 1e-14;
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(columns);
  for (int i = 0; i < columns; ++i) {
    inverse[i] = values[i] > floor ? 1.0 / values[i] : 0.0;
  }
  out.matrix = eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
  return out;
}

// Each camera's standard deviations after the joint solve (its corners' own fit knew only the
// corners), and the depth scale's uncertainty they imply.
std::expected<void, std::string> cameraUncertainty(ceres::Problem& problem,
                                                   const std::vector<CameraParams>& cams,
                                                   CamerasFit& cameras) {
  const auto covariance = solutionCovariance(problem);
  if (!covariance) {
    return std::unexpected(covariance.error());
  }
  const Eigen::MatrixXd& m = covariance->matrix;
  for (std::size_t c = 0; c < cams.size(); ++c) {
    CameraFit& fit = cameras.cameras[c];
    fit.sd.fill(0.0);
    const int k = covariance->offsetOf(cams[c].intrinsics.data());
    if (k < 0) {
      continue;
    }
    for (int i = 0; i < 4; ++i) {
      fit.sd[static_cast<std::size_t>(i)] = std::sqrt(std::max(0.0, m(k + i, k + i)));
    }
    // The lens block's tangent space leaves out k3 when it is held at the nominal.
    if (const int l = covariance->offsetOf(cams[c].lens.data()); l >= 0) {
      const int free = problem.ParameterBlockTangentSize(cams[c].lens.data());
      for (int i = 0; i < free; ++i) {
        fit.sd[4 + static_cast<std::size_t>(i)] = std::sqrt(std::max(0.0, m(l + i, l + i)));
      }
    }
    // Depth scales with the focal length: the variance of (fx/f̂x + fy/f̂y)/2.
    const double fx = cams[c].intrinsics[0];
    const double fy = cams[c].intrinsics[1];
    const double scaleVariance =
        (m(k, k) / (fx * fx) + 2 * m(k, k + 1) / (fx * fy) + m(k + 1, k + 1) / (fy * fy)) / 4;
    fit.depthScaleSdMm = std::sqrt(std::max(0.0, scaleVariance)) * 1000.0;
  }
  return {};
}

}  // namespace

std::expected<JointFigures, std::string> refineJointly(
    const CaptureSet& set, const algo::Rig& nominal, CamerasFit& cameras,
    std::vector<ProjectorFit>& projectors, const std::vector<std::vector<StripeSample>>& samples) {
  JointFigures figures;
  double cornerSum = 0.0;
  int cornerCount = 0;
  for (const CameraFit& fit : cameras.cameras) {
    cornerSum += fit.rmsPx * fit.rmsPx;
    ++cornerCount;
  }
  figures.cornerSigmaPx = std::max(kMinCornerSigmaPx, std::sqrt(cornerSum / cornerCount));
  double stripeSum = 0.0;
  for (const ProjectorFit& fit : projectors) {
    stripeSum += fit.rmsPx * fit.rmsPx;
  }
  figures.stripeSigmaPx = std::max(
      kMinStripeSigmaPx,
      std::sqrt(stripeSum / static_cast<double>(std::max<std::size_t>(projectors.size(), 1))));

  std::vector<CameraParams> cams(cameras.cameras.size());
  for (std::size_t c = 0; c < cams.size(); ++c) {
    const algo::Camera& cam = cameras.cameras[c].camera;
    cams[c].intrinsics = {cam.fx(), cam.fy(), cam.cx(), cam.cy()};
    cams[c].lens = {cam.dist[0], cam.dist[1], cam.dist[2], cam.dist[3], cam.dist[4]};
    cams[c].rotation =
        angleAxis(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(cam.R.data()));
    cams[c].t = {cam.t[0], cam.t[1], cam.t[2]};
  }
  std::vector<PoseParams> poses(set.poses.size());
  for (std::size_t v = 0; v < poses.size(); ++v) {
    const TargetPose& pose = cameras.targets[v];
    poses[v].rotation = angleAxis(pose.R);
    poses[v].t = {pose.t[0], pose.t[1], pose.t[2]};
  }
  std::vector<ProjectorConstants> constants;
  std::vector<ProjectorParams> projs;
  for (std::size_t p = 0; p < projectors.size(); ++p) {
    constants.emplace_back(nominal.projectors[p]);
    projs.push_back(detail::paramsOf(projectors[p].projector));
    projs.back().intrinsics = {projectors[p].projector.fx() / nominal.projectors[p].fx(), 0.0};
    // The shift along the axis, from the fitted principal point.
    const double du = projectors[p].projector.cx() - constants[p].cx;
    const double dv = projectors[p].projector.cy() - constants[p].cy;
    projs.back().intrinsics[1] = du * constants[p].cosA + dv * constants[p].sinA;
  }

  ceres::Problem problem;
  const std::vector<TargetPoint> corners = innerCorners(set.target);
  for (std::size_t c = 0; c < cams.size(); ++c) {
    for (std::size_t v = 0; v < set.poses.size(); ++v) {
      const auto& found = cameras.cameras[c].corners[v];
      for (std::size_t i = 0; i < found.size(); ++i) {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<CornerResidual, 2, 4, 5, 3, 3, 3, 3>(
                new CornerResidual{{corners[i].x, corners[i].y}, found[i], figures.cornerSigmaPx}),
            new ceres::HuberLoss(kHuberSigmas), cams[c].intrinsics.data(), cams[c].lens.data(),
            cams[c].rotation.data(), cams[c].t.data(), poses[v].rotation.data(), poses[v].t.data());
      }
    }
  }
  const double stripeSigma = figures.stripeSigmaPx / std::sqrt(kStripeSampleShare);
  for (std::size_t p = 0; p < projs.size(); ++p) {
    for (const StripeSample& s : projectors[p].inliers) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<StripeResidual, 1, 4, 5, 3, 3, 3, 3, 3, 3, 2, 4>(
              new StripeResidual{&s, &constants[p], stripeSigma}),
          new ceres::HuberLoss(kHuberSigmas), cams[s.camera].intrinsics.data(),
          cams[s.camera].lens.data(), cams[s.camera].rotation.data(), cams[s.camera].t.data(),
          poses[s.pose].rotation.data(), poses[s.pose].t.data(), projs[p].rotation.data(),
          projs[p].centre.data(), projs[p].intrinsics.data(), projs[p].lens.data());
    }
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<CentrePrior, 1, 3>(
                                 new CentrePrior(nominal.projectors[p], constants[p])),
                             nullptr, projs[p].centre.data());
    const auto& d = nominal.projectors[p].dist;
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<detail::LensPrior, 4, 4>(
            new detail::LensPrior{.nominal = {d[0], d[1], d[2], d[3]}, .scale = 1.0}),
        nullptr, projs[p].lens.data());
  }
  // The first camera is the world frame; lens terms its own fit fixed stay fixed.
  problem.SetParameterBlockConstant(cams[0].rotation.data());
  problem.SetParameterBlockConstant(cams[0].t.data());
  for (std::size_t c = 0; c < cams.size(); ++c) {
    if (problem.HasParameterBlock(cams[c].lens.data()) &&
        std::ranges::find(cameras.cameras[c].fixedAtNominal, "k3") !=
            cameras.cameras[c].fixedAtNominal.end()) {
      problem.SetManifold(cams[c].lens.data(), new ceres::SubsetManifold(5, {4}));
    }
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-10;
  options.num_threads = 2;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  figures.iterations = static_cast<int>(summary.iterations.size());
  figures.converged = summary.termination_type == ceres::CONVERGENCE;
  if (!summary.IsSolutionUsable()) {
    return std::unexpected("the joint refinement failed: " + summary.message);
  }

  if (auto sd = cameraUncertainty(problem, cams, cameras); !sd) {
    return std::unexpected(sd.error());
  }

  // Write back, then measure every residual again with the rig as it now is.
  for (std::size_t c = 0; c < cams.size(); ++c) {
    algo::Camera& cam = cameras.cameras[c].camera;
    const auto& k = cams[c].intrinsics;
    cam.K = {k[0], 0, k[2], 0, k[1], k[3], 0, 0, 1};
    for (std::size_t i = 0; i < 5; ++i) {
      cam.dist[i] = cams[c].lens[i];
    }
    const Eigen::Matrix3d rot = matrix(cams[c].rotation);
    for (int i = 0; i < 9; ++i) {
      cam.R[static_cast<std::size_t>(i)] = rot(i / 3, i % 3);
    }
    cam.t = cams[c].t;
  }
  for (std::size_t v = 0; v < poses.size(); ++v) {
    if (cameras.targets[v].known) {
      cameras.targets[v].R = matrix(poses[v].rotation);
      cameras.targets[v].t = Eigen::Vector3d(poses[v].t[0], poses[v].t[1], poses[v].t[2]);
    }
  }
  for (std::size_t c = 0; c < cams.size(); ++c) {
    CameraFit& fit = cameras.cameras[c];
    std::vector<double> all;
    for (std::size_t v = 0; v < set.poses.size(); ++v) {
      std::vector<double> pose;
      for (std::size_t i = 0; i < fit.corners[v].size(); ++i) {
        const TargetPose& tp = cameras.targets[v];
        const Eigen::Vector3d world = tp.R * Eigen::Vector3d(corners[i].x, corners[i].y, 0) + tp.t;
        const auto q = algo::lens::project(fit.camera, {world[0], world[1], world[2]});
        if (q) {
          pose.push_back(q->x - fit.corners[v][i][0]);
          pose.push_back(q->y - fit.corners[v][i][1]);
        }
      }
      if (!pose.empty()) {
        // Per corner, as OpenCV reports it: the RMS of the 2-D distance.
        fit.poses[v].rmsPx = rms(pose) * std::sqrt(2.0);
        all.insert(all.end(), pose.begin(), pose.end());
      }
    }
    fit.rmsPx = rms(all) * std::sqrt(2.0);
  }
  for (std::size_t p = 0; p < projs.size(); ++p) {
    ProjectorFit& fit = projectors[p];
    fit.projector = detail::projectorOf(nominal.projectors[p], constants[p], projs[p]);
    for (StripeSample& s : fit.inliers) {
      if (const auto point =
              targetPoint(cameras.cameras[s.camera].camera, cameras.targets[s.pose], s.x, s.y)) {
        s.point = *point;
      }
    }
    measureResiduals(fit, samples[p], set);
  }
  return figures;
}

}  // namespace smx::calib
