#include "point_cloud.hpp"

#include "smx/algo/lens.hpp"

namespace smx::host {

std::vector<sim::PlyPoint> depthToWorldPoints(const algo::Camera& camera,
                                              algo::ConstDepthPlane depth, double depthUnitM,
                                              std::optional<algo::ConstRgbView> colours) {
  std::vector<sim::PlyPoint> points;
  for (int y = 0; y < depth.height(); ++y) {
    for (int x = 0; x < depth.width(); ++x) {
      const std::uint16_t units = depth(x, y);
      if (units == algo::kNoDepth) {
        continue;
      }
      const auto local = algo::lens::devicePoint(
          camera, {static_cast<double>(x), static_cast<double>(y)}, units * depthUnitM);
      if (!local) {
        continue;
      }
      const auto world = algo::lens::toWorld(camera, *local);
      sim::PlyPoint p{};
      p.x = static_cast<float>(world[0]);
      p.y = static_cast<float>(world[1]);
      p.z = static_cast<float>(world[2]);
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
