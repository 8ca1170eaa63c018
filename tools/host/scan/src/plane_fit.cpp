#include "plane_fit.hpp"

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>

#include <cmath>
#include <vector>

#include "open3d_bridge.hpp"

namespace smx::scan::detail {

PlaneFit planeFit(const Cloud& source, const Cloud& target, const Pose& pose, double maxDistanceM) {
  PlaneFit fit;
  if (source.empty() || target.empty() || target.normals.size() != target.size()) {
    return fit;
  }
  const auto target3d = toOpen3d(target);
  const open3d::geometry::KDTreeFlann tree(*target3d);
  std::vector<int> index(1);
  std::vector<double> squared(1);
  const double maxSquared = maxDistanceM * maxDistanceM;
  double sum = 0.0;
  std::size_t inliers = 0;
  for (const auto& p : source.points) {
    const Eigen::Vector3d q = pose * p;
    if (tree.SearchKNN(q, 1, index, squared) < 1 || squared[0] > maxSquared) {
      continue;
    }
    const auto i = static_cast<std::size_t>(index[0]);
    const double along = target.normals[i].dot(q - target.points[i]);
    sum += along * along;
    ++inliers;
  }
  fit.fitness = static_cast<double>(inliers) / static_cast<double>(source.size());
  fit.rmseM = inliers > 0 ? std::sqrt(sum / static_cast<double>(inliers)) : 0.0;
  return fit;
}

}  // namespace smx::scan::detail
