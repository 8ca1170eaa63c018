#pragma once

#include "smx/scan/points.hpp"
#include "smx/scan/range_view.hpp"

// How well a registered cloud lies on its target, measured along the target's normals: the
// distance to the surface, not to the nearest sample (Open3D's inlier RMSE is point to point,
// which on a grid of voxel v never drops much below v / 3 however right the pose).
namespace smx::scan::detail {

struct PlaneFit {
  double fitness = 0.0;  // share of source points with a target point within maxDistanceM
  double rmseM = 0.0;    // RMS of n · (pose·p − q) over those pairs
};

// `target` needs normals.
[[nodiscard]] PlaneFit planeFit(const Cloud& source, const Cloud& target, const Pose& pose,
                                double maxDistanceM);

}  // namespace smx::scan::detail
