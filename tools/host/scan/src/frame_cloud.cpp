#include "frame_cloud.hpp"

#include <cmath>
#include <limits>

#include "smx/algo/lens.hpp"

namespace smx::scan::detail {

FrameCloud::FrameCloud(const algo::Rig& rig, const FrameCloudOptions& options) : options_(options) {
  const int step = std::max(options_.step, 1);
  options_.step = step;
  for (const auto& camera : rig.cameras) {
    CameraTable table{
        camera, {}, (camera.width + step - 1) / step, (camera.height + step - 1) / step};
    table.rays.reserve(static_cast<std::size_t>(table.columns) *
                       static_cast<std::size_t>(table.rows));
    for (int r = 0; r < table.rows; ++r) {
      for (int c = 0; c < table.columns; ++c) {
        const auto p = algo::lens::devicePoint(
            camera, {static_cast<double>(c * step), static_cast<double>(r * step)}, 1.0);
        table.rays.push_back(
            p ? Eigen::Vector3d((*p)[0], (*p)[1], (*p)[2])
              : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
      }
    }
    cameras_.push_back(std::move(table));
  }
}

Cloud FrameCloud::points(const RangeView& view) const {
  Cloud out;
  const std::size_t count = std::min(cameras_.size(), view.cameras.size());
  for (std::size_t ci = 0; ci < count; ++ci) {
    const CameraTable& t = cameras_[ci];
    const CameraRange& range = view.cameras[ci];
    if (range.width != t.camera.width || range.height != t.camera.height ||
        range.depth.size() !=
            static_cast<std::size_t>(range.width) * static_cast<std::size_t>(range.height)) {
      continue;
    }
    // Device-frame points of the sampled grid (z = 0: none).
    std::vector<Eigen::Vector3d> grid(t.rays.size(), Eigen::Vector3d::Zero());
    for (int r = 0; r < t.rows; ++r) {
      for (int c = 0; c < t.columns; ++c) {
        const auto x = static_cast<std::size_t>(c) * static_cast<std::size_t>(options_.step);
        const auto y = static_cast<std::size_t>(r) * static_cast<std::size_t>(options_.step);
        const double z =
            range.depth[y * static_cast<std::size_t>(range.width) + x] * view.depthUnitM;
        const std::size_t i = static_cast<std::size_t>(r) * static_cast<std::size_t>(t.columns) +
                              static_cast<std::size_t>(c);
        if (z >= options_.minDepthM && z <= options_.maxDepthM && t.rays[i].allFinite()) {
          grid[i] = z * t.rays[i];
        }
      }
    }
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> rotation(
        t.camera.R.data());
    const Eigen::Vector3d tr(t.camera.t[0], t.camera.t[1], t.camera.t[2]);
    const auto at = [&](int c, int r) -> const Eigen::Vector3d& {
      return grid[static_cast<std::size_t>(r) * static_cast<std::size_t>(t.columns) +
                  static_cast<std::size_t>(c)];
    };
    const auto near = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
      return b.z() > 0 && std::abs(a.z() - b.z()) <= options_.maxDepthJump * a.z();
    };
    for (int r = 1; r + 1 < t.rows; ++r) {
      for (int c = 1; c + 1 < t.columns; ++c) {
        const Eigen::Vector3d& p = at(c, r);
        if (!(p.z() > 0)) {
          continue;
        }
        const Eigen::Vector3d& left = at(c - 1, r);
        const Eigen::Vector3d& right = at(c + 1, r);
        const Eigen::Vector3d& up = at(c, r - 1);
        const Eigen::Vector3d& down = at(c, r + 1);
        if (!near(p, left) || !near(p, right) || !near(p, up) || !near(p, down)) {
          continue;  // an edge or a hole: no reliable normal
        }
        Eigen::Vector3d n = (right - left).cross(down - up);
        const double length = n.norm();
        if (!(length > 0)) {
          continue;
        }
        n /= length;
        if (n.dot(p) > 0) {
          n = -n;  // towards the camera
        }
        // Device → rig world: X = Rᵀ·(x − t).
        out.points.emplace_back(rotation.transpose() * (p - tr));
        out.normals.emplace_back(rotation.transpose() * n);
      }
    }
  }
  return out;
}

}  // namespace smx::scan::detail
