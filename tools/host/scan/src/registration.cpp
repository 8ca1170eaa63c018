#include "smx/scan/registration.hpp"

#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/CorrespondenceChecker.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/RobustKernel.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/utility/Random.h>

#include <cmath>
#include <functional>

#include "open3d_bridge.hpp"

namespace smx::scan {
namespace {

namespace reg = open3d::pipelines::registration;
using open3d::geometry::PointCloud;

std::shared_ptr<PointCloud> atVoxel(const PointCloud& cloud, double voxelM) {
  auto out = cloud.VoxelDownSample(voxelM);
  if (out->HasNormals()) {
    out->NormalizeNormals();
  }
  return out;
}

std::optional<std::string> optionsProblem(const IcpOptions& options) {
  if (options.levelVoxelsM.empty()) {
    return "ICP needs at least one level";
  }
  for (const double v : options.levelVoxelsM) {
    if (!std::isfinite(v) || v <= 0) {
      return "ICP level voxels must be positive";
    }
  }
  if (!(options.maxDistanceVoxels > 0) || !(options.kernelVoxels > 0) ||
      options.iterationsPerLevel < 1) {
    return "ICP distances and iterations must be positive";
  }
  return std::nullopt;
}

}  // namespace

std::expected<Registration, std::string> registerIcp(const Cloud& source, const Cloud& target,
                                                     const Pose& initial,
                                                     const IcpOptions& options) {
  if (auto problem = optionsProblem(options)) {
    return std::unexpected(*problem);
  }
  if (source.empty() || target.empty()) {
    return std::unexpected("cannot register an empty cloud");
  }
  if (target.normals.size() != target.size()) {
    return std::unexpected("the target of point-to-plane ICP needs normals");
  }
  const auto source3d = detail::toOpen3d(source);
  const auto target3d = detail::toOpen3d(target);
  Eigen::Matrix4d pose = initial.matrix();
  reg::RegistrationResult result;
  double maxDistance = 0;
  std::shared_ptr<PointCloud> src;
  std::shared_ptr<PointCloud> tgt;
  for (const double voxel : options.levelVoxelsM) {
    src = atVoxel(*source3d, voxel);
    tgt = atVoxel(*target3d, voxel);
    maxDistance = options.maxDistanceVoxels * voxel;
    // Tukey: residuals beyond the kernel width (other surfaces, outliers) weigh nothing.
    const reg::TransformationEstimationPointToPlane estimation(
        std::make_shared<reg::TukeyLoss>(options.kernelVoxels * voxel));
    result =
        reg::RegistrationICP(*src, *tgt, maxDistance, pose, estimation,
                             reg::ICPConvergenceCriteria(1e-7, 1e-7, options.iterationsPerLevel));
    pose = result.transformation_;
  }
  // A surface that does not fix every degree of freedom (a sphere, a plane) leaves the
  // point-to-plane system singular and ICP can run away from a good start: keep the start when
  // it fits better than where ICP ended.
  const auto start = reg::EvaluateRegistration(*src, *tgt, maxDistance, initial.matrix());
  if (!pose.allFinite() || result.fitness_ < start.fitness_ - 0.01) {
    result = start;
    pose = initial.matrix();
  }
  Registration out;
  out.pose = Pose(pose);
  out.fitness = result.fitness_;
  out.inlierRmseM = result.inlier_rmse_;
  out.information = reg::GetInformationMatrixFromPointClouds(*src, *tgt, maxDistance, pose);
  return out;
}

std::optional<Registration> alignGlobal(const Cloud& source, const Cloud& target,
                                        const GlobalOptions& options, const IcpOptions& refine) {
  if (source.empty() || target.empty() || target.normals.size() != target.size() ||
      source.normals.size() != source.size() || !(options.voxelM > 0)) {
    return std::nullopt;
  }
  const double voxel = options.voxelM;
  const auto src = atVoxel(*detail::toOpen3d(source), voxel);
  const auto tgt = atVoxel(*detail::toOpen3d(target), voxel);
  const open3d::geometry::KDTreeSearchParamHybrid featureSearch(5 * voxel, 100);
  const auto srcFeatures = reg::ComputeFPFHFeature(*src, featureSearch);
  const auto tgtFeatures = reg::ComputeFPFHFeature(*tgt, featureSearch);
  const double distance = 1.5 * voxel;
  const reg::CorrespondenceCheckerBasedOnEdgeLength edges(0.9);
  const reg::CorrespondenceCheckerBasedOnDistance distances(distance);
  open3d::utility::random::Seed(static_cast<int>(options.seed));
  const auto coarse = reg::RegistrationRANSACBasedOnFeatureMatching(
      *src, *tgt, *srcFeatures, *tgtFeatures, true, distance,
      reg::TransformationEstimationPointToPoint(false), 3, {std::cref(edges), std::cref(distances)},
      reg::RANSACConvergenceCriteria(options.maxIterations, options.confidence));
  if (coarse.correspondence_set_.size() < 3) {
    return std::nullopt;
  }
  auto refined = registerIcp(source, target, Pose(coarse.transformation_), refine);
  if (!refined || refined->fitness < options.minFitness) {
    return std::nullopt;
  }
  return *refined;
}

}  // namespace smx::scan
