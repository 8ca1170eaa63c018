#include "smx/algo/encoding_prediction.hpp"

#include <cmath>
#include <optional>

#include "smx/algo/fixed_math.hpp"
#include "smx/algo/lens.hpp"
#include "smx/algo/pattern_image.hpp"

namespace smx::algo {

namespace {

// The stripe coordinate of the point seen at camera pixel (x, y) on the plane z_cam = depth.
std::optional<double> stripeAt(const Camera& cam, const Projector& proj, double x, double y,
                               double depth) {
  const auto ray = lens::pixelRay(cam, {x, y});
  if (!ray) {
    return std::nullopt;
  }
  // z_cam of origin + s·direction is linear in s: z = (R·origin + t).z + s·(R·direction).z.
  const auto& r = cam.R;
  const double z0 =
      r[6] * ray->origin[0] + r[7] * ray->origin[1] + r[8] * ray->origin[2] + cam.t[2];
  const double dz = r[6] * ray->direction[0] + r[7] * ray->direction[1] + r[8] * ray->direction[2];
  if (!(dz > 0.0)) {
    return std::nullopt;
  }
  const double s = (depth - z0) / dz;
  const lens::Point3 point = {ray->origin[0] + s * ray->direction[0],
                              ray->origin[1] + s * ray->direction[1],
                              ray->origin[2] + s * ray->direction[2]};
  const auto uv = lens::project(proj, point);
  if (!uv) {
    return std::nullopt;
  }
  return stripeCoordinate(proj.pattern, proj.width, proj.height, uv->x, uv->y);
}

std::optional<std::uint16_t> angleAt(const Camera& cam, const Projector& proj, double x, double y,
                                     double depth) {
  const auto s0 = stripeAt(cam, proj, x, y, depth);
  const auto sx = stripeAt(cam, proj, x + 1.0, y, depth);
  const auto sy = stripeAt(cam, proj, x, y + 1.0, depth);
  if (!s0 || !sx || !sy) {
    return std::nullopt;
  }
  const double gx = *sx - *s0;
  const double gy = *sy - *s0;
  if (!(std::hypot(gx, gy) > 1e-9)) {
    return std::nullopt;
  }
  return BinAngle::fromRadians(std::atan2(gy, gx)).raw;
}

}  // namespace

std::expected<std::vector<std::uint16_t>, std::string> predictEncodingAngles(
    const Rig& rig, int camera, const DemuxLayout& layout, double nominalDepthM) {
  if (camera < 0 || static_cast<std::size_t>(camera) >= rig.cameras.size()) {
    return std::unexpected("no camera " + std::to_string(camera) + " in the rig");
  }
  const Camera& cam = rig.cameras[static_cast<std::size_t>(camera)];
  if (cam.width != layout.width || cam.height != layout.height) {
    return std::unexpected("camera " + cam.id + " is not the layout's size");
  }
  if (rig.projectors.size() != static_cast<std::size_t>(layout.projectors)) {
    return std::unexpected("the rig's projector count differs from the layout's");
  }
  if (!(nominalDepthM > 0.0)) {
    return std::unexpected("the nominal depth must be positive");
  }
  const auto projectors = static_cast<std::size_t>(layout.projectors);
  std::vector<std::uint16_t> angles(layout.tileCount() * projectors);
  const int t = layout.params.tilePx;
  for (std::size_t p = 0; p < projectors; ++p) {
    const Projector& proj = rig.projectors[p];
    const auto centre =
        angleAt(cam, proj, (cam.width - 1) / 2.0, (cam.height - 1) / 2.0, nominalDepthM);
    if (!centre) {
      return std::unexpected("projector " + proj.id + " does not light the centre of camera " +
                             cam.id + " at the nominal depth");
    }
    for (int ty = 0; ty < layout.tilesY(); ++ty) {
      for (int tx = 0; tx < layout.tilesX(); ++tx) {
        const double x = tx * t + (t - 1) / 2.0;
        const double y = ty * t + (t - 1) / 2.0;
        const auto tile = static_cast<std::size_t>(ty) * static_cast<std::size_t>(layout.tilesX()) +
                          static_cast<std::size_t>(tx);
        angles[tile * projectors + p] = angleAt(cam, proj, x, y, nominalDepthM).value_or(*centre);
      }
    }
  }
  return angles;
}

}  // namespace smx::algo
