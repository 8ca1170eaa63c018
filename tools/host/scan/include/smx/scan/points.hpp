#pragma once

#include <Eigen/Core>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/scan/range_view.hpp"

// Range images as oriented point clouds in the rig's world frame (metres), the input of
// registration and the output of fusion (docs/scanning.md). Host only.
namespace smx::scan {

// Points with, when known, unit normals and RGB colours in [0, 1] (each either empty or as long
// as `points`).
struct Cloud {
  std::vector<Eigen::Vector3d> points{};
  std::vector<Eigen::Vector3d> normals{};
  std::vector<Eigen::Vector3d> colours{};

  [[nodiscard]] bool empty() const { return points.empty(); }
  [[nodiscard]] std::size_t size() const { return points.size(); }
};

struct CloudOptions {
  double voxelM = 0.001;       // voxel of the downsampled cloud; 0 keeps every point
  double normalRadiusM = 0.0;  // neighbourhood of the normal estimate; 0 = 3 × voxelM (≥ 2 mm)
  int normalNeighbours = 30;   // at most this many neighbours in that radius
};

// One camera's range image → its points in the rig's world frame: pixel (x, y) with z ≠ 0 is
// z·(x_n, y_n, 1) with (x_n, y_n) undistorted by the camera's lens (algo::lens), then Rᵀ·(p − t).
// Colours from range.colour when present. No normals, no downsampling. `range` must be
// camera.width × camera.height (readViewsFolder checks it).
[[nodiscard]] Cloud cameraPoints(const algo::Camera& camera, const CameraRange& range,
                                 double depthUnitM);

// A view's cloud: each camera's points downsampled to options.voxelM, normals estimated and
// oriented towards that camera's centre, then all cameras merged and downsampled again (normals
// averaged and renormalised). view.cameras follows rig.cameras; extra or missing cameras are
// ignored.
[[nodiscard]] Cloud viewCloud(const algo::Rig& rig, const RangeView& view,
                              const CloudOptions& options = {});

// The cloud moved by `pose` (points and normals).
[[nodiscard]] Cloud transformed(const Cloud& cloud, const Pose& pose);

// The cloud on a voxel grid of `voxelM` (the mean of each voxel's points, normals renormalised).
[[nodiscard]] Cloud downsampled(const Cloud& cloud, double voxelM);

// Appends `more` to `cloud` (normals and colours kept only when both clouds have them).
void append(Cloud& cloud, const Cloud& more);

}  // namespace smx::scan
