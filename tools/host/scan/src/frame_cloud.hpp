#pragma once

#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/scan/points.hpp"
#include "smx/scan/range_view.hpp"

// A range view as oriented points fast enough for every frame of a hand-held scan: each camera's
// depth image is read at every `step`-th pixel through a table of undistorted rays built once,
// and normals come from the image grid (the cross product of the neighbours' differences), not
// from a neighbour search.
namespace smx::scan::detail {

struct FrameCloudOptions {
  int step = 2;             // every step-th pixel in x and y
  double minDepthM = 0.15;  // nearer or farther depths are not the scanned object
  double maxDepthM = 1.5;
  // Neighbours differing in depth by more than this share of the depth are across an edge: no
  // normal there.
  double maxDepthJump = 0.02;
};

class FrameCloud {
 public:
  FrameCloud(const algo::Rig& rig, const FrameCloudOptions& options);

  // Points and unit normals (towards the camera) in the rig's world frame. Cameras whose image
  // is not the rig's size are skipped.
  [[nodiscard]] Cloud points(const RangeView& view) const;

 private:
  struct CameraTable {
    algo::Camera camera;
    std::vector<Eigen::Vector3d> rays;  // per sampled pixel: (x_n, y_n, 1), NaN if none
    int columns = 0;
    int rows = 0;
  };

  FrameCloudOptions options_;
  std::vector<CameraTable> cameras_;
};

}  // namespace smx::scan::detail
