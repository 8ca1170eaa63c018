#include "point_cloud.hpp"

#include "smx/algo/lens.hpp"

namespace smx::host {

std::vector<sim::PlyPoint> depthToWorldPoints(const algo::Camera& camera,
                                              algo::ConstDepthPlane depth, double depthUnitM,
                                              std::optional<algo::ConstRgbView> colours) {
  std::vector<sim::PlyPoint> points;
  const auto& r = camera.R;
  const auto& t = camera.t;
  for (int y = 0; y < depth.height(); ++y) {
    for (int x = 0; x < depth.width(); ++x) {
      const std::uint16_t units = depth(x, y);
      if (units == algo::kNoDepth) {
        continue;
      }
      const auto n = algo::lens::undistort(
          camera.dist, {(x - camera.cx()) / camera.fx(), (y - camera.cy()) / camera.fy()});
      if (!n) {
        continue;
      }
      const double z = units * depthUnitM;
      const double c[3] = {n->x * z - t[0], n->y * z - t[1], z - t[2]};
      sim::PlyPoint p{};
      p.x = static_cast<float>(r[0] * c[0] + r[3] * c[1] + r[6] * c[2]);
      p.y = static_cast<float>(r[1] * c[0] + r[4] * c[1] + r[7] * c[2]);
      p.z = static_cast<float>(r[2] * c[0] + r[5] * c[1] + r[8] * c[2]);
      const algo::Rgb8 rgb = colours ? (*colours)(x, y) : algo::Rgb8{200, 200, 200};
      p.r = rgb.r;
      p.g = rgb.g;
      p.b = rgb.b;
      points.push_back(p);
    }
  }
  return points;
}

}  // namespace smx::host
