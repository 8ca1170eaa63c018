#include "smx/health/cross_camera.hpp"

#include <cmath>
#include <cstddef>
#include <limits>

#include "smx/algo/lens.hpp"

namespace smx::health {

namespace {

// Four neighbours whose depths spread more than this share of their depth straddle an edge:
// interpolating between them would invent a surface.
constexpr double kMaxNeighbourSpread = 0.01;

// Bilinear depth (units) of `depth` at (u, v); NaN unless all four neighbours have depth and agree.
double sampleDepth(const CameraDepths& d, const std::vector<std::uint16_t>& depth, double u,
                   double v) {
  const int x = static_cast<int>(std::floor(u));
  const int y = static_cast<int>(std::floor(v));
  if (x < 0 || y < 0 || x + 1 >= d.width || y + 1 >= d.height) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double z00 = depth[d.index(x, y)];
  const double z10 = depth[d.index(x + 1, y)];
  const double z01 = depth[d.index(x, y + 1)];
  const double z11 = depth[d.index(x + 1, y + 1)];
  const double lo = std::min(std::min(z00, z10), std::min(z01, z11));
  const double hi = std::max(std::max(z00, z10), std::max(z01, z11));
  if (lo == algo::kNoDepth || hi - lo > kMaxNeighbourSpread * hi) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double fx = u - x;
  const double fy = v - y;
  return (1 - fy) * ((1 - fx) * z00 + fx * z10) + fy * ((1 - fx) * z01 + fx * z11);
}

}  // namespace

DisagreementField crossCameraField(const algo::Rig& rig, const CameraDepths& first,
                                   const CameraDepths& second, int projector) {
  const algo::Camera& cam0 = rig.cameras.at(static_cast<std::size_t>(first.camera));
  const algo::Camera& cam1 = rig.cameras.at(static_cast<std::size_t>(second.camera));
  const auto& depth0 = first.depth.at(static_cast<std::size_t>(projector));
  const auto& depth1 = second.depth.at(static_cast<std::size_t>(projector));
  DisagreementField field{
      first.width, first.height,
      std::vector<double>(first.depth.front().size(), std::numeric_limits<double>::quiet_NaN())};
  for (int y = 0; y < second.height; ++y) {
    for (int x = 0; x < second.width; ++x) {
      const std::uint16_t z = depth1[second.index(x, y)];
      if (z == algo::kNoDepth) {
        continue;
      }
      const auto local = algo::lens::devicePoint(
          cam1, {static_cast<double>(x), static_cast<double>(y)}, z * second.depthUnitM);
      if (!local) {
        continue;
      }
      const auto world = algo::lens::toWorld(cam1, *local);
      const auto pixel = algo::lens::project(cam0, world);
      if (!pixel) {
        continue;
      }
      const double sampled = sampleDepth(first, depth0, pixel->x, pixel->y);
      if (std::isnan(sampled)) {
        continue;
      }
      const double z0 = algo::lens::toDevice(cam0, world)[2];
      const int u = static_cast<int>(std::lround(pixel->x));
      const int v = static_cast<int>(std::lround(pixel->y));
      field.mm[first.index(u, v)] =
          atReferenceDistance((sampled * first.depthUnitM - z0) * 1000.0, z0);
    }
  }
  return field;
}

}  // namespace smx::health
