#include "smx/scan/table_crop.hpp"

#include "smx/algo/lens.hpp"

namespace smx::scan {

void keepOnTable(RangeView& view, const algo::Rig& rig, const TurntableAxis& axis, double radiusM) {
  const Eigen::Vector3d a = axis.direction.normalized();
  const double limit = radiusM * radiusM;
  for (std::size_t c = 0; c < view.cameras.size() && c < rig.cameras.size(); ++c) {
    const algo::Camera& camera = rig.cameras[c];
    CameraRange& range = view.cameras[c];
    if (range.width != camera.width || range.height != camera.height) {
      continue;  // readViewsFolder and the device check sizes; nothing to crop in a stranger
    }
    for (int y = 0; y < range.height; ++y) {
      for (int x = 0; x < range.width; ++x) {
        std::uint16_t& z =
            range.depth[static_cast<std::size_t>(y) * static_cast<std::size_t>(range.width) +
                        static_cast<std::size_t>(x)];
        if (z == 0) {
          continue;
        }
        const auto local = algo::lens::devicePoint(
            camera, {static_cast<double>(x), static_cast<double>(y)}, z * view.depthUnitM);
        if (!local) {
          z = 0;
          continue;
        }
        const auto w = algo::lens::toWorld(camera, *local);
        const Eigen::Vector3d d = Eigen::Vector3d(w[0], w[1], w[2]) - axis.point;
        if (d.cross(a).squaredNorm() > limit) {
          z = 0;
        }
      }
    }
  }
}

}  // namespace smx::scan
