// Init time: the triangulation tables of one projector–camera pair (triangulation.hpp), in
// double, then scaled to integers.
#include <algorithm>
#include <cmath>
#include <string>

#include "smx/algo/lens.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/algo/triangulation.hpp"

namespace smx::algo {

namespace {

using Mat3 = std::array<double, 9>;
using Vec3 = std::array<double, 3>;

Vec3 mul(const Mat3& m, const Vec3& v) {
  return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
          m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}

double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// a · bᵀ for rotations: (R_p · R_cᵀ).
Mat3 mulTransposed(const Mat3& a, const Mat3& b) {
  Mat3 out{};
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c) {
      double v = 0;
      for (std::size_t k = 0; k < 3; ++k) {
        v += a[r * 3 + k] * b[c * 3 + k];
      }
      out[r * 3 + c] = v;
    }
  }
  return out;
}

}  // namespace

double baselineM(const Rig& rig, int camera, int projector) {
  const lens::Point3 c = lens::centre(rig.cameras.at(static_cast<std::size_t>(camera)));
  const lens::Point3 p = lens::centre(rig.projectors.at(static_cast<std::size_t>(projector)));
  return std::hypot(c[0] - p[0], c[1] - p[1], c[2] - p[2]);
}

std::expected<TriangulationTables, std::string> buildTriangulationTables(const Rig& rig, int camera,
                                                                         int projector,
                                                                         double depthUnitM) {
  if (camera < 0 || camera >= static_cast<int>(rig.cameras.size())) {
    return std::unexpected("triangulation: no camera " + std::to_string(camera) + " in the rig");
  }
  if (projector < 0 || projector >= static_cast<int>(rig.projectors.size())) {
    return std::unexpected("triangulation: no projector " + std::to_string(projector) +
                           " in the rig");
  }
  if (!(depthUnitM > 0.0) || !std::isfinite(depthUnitM)) {
    return std::unexpected("triangulation: the depth unit must be positive");
  }
  const Camera& cam = rig.cameras[static_cast<std::size_t>(camera)];
  const Projector& proj = rig.projectors[static_cast<std::size_t>(projector)];
  if (std::any_of(proj.dist.begin(), proj.dist.end(), [](double k) { return k != 0.0; })) {
    return std::unexpected("projector '" + proj.id +
                           "': lens distortion is not supported for projectors; dist must be all "
                           "zero (docs/triangulation.md)");
  }
  // s = s00 + du·u + dv·v over projector pixels; with u = fx·X/Z + cx, v = fy·Y/Z + cy the
  // plane of s is n₀ − s·e_z with n₀ = (du·fx, dv·fy, s00 + du·cx + dv·cy).
  const double s00 = stripeCoordinate(proj.pattern, proj.width, proj.height, 0.0, 0.0);
  const double du = stripeCoordinate(proj.pattern, proj.width, proj.height, 1.0, 0.0) - s00;
  const double dv = stripeCoordinate(proj.pattern, proj.width, proj.height, 0.0, 1.0) - s00;
  if (!std::isfinite(s00) || (du == 0.0 && dv == 0.0)) {
    return std::unexpected("projector '" + proj.id + "': the stripe pattern is degenerate");
  }
  const Vec3 n0{du * proj.fx(), dv * proj.fy(), s00 + du * proj.cx() + dv * proj.cy()};
  // Camera → projector: X_p = M·X_c + m, M = R_p·R_cᵀ, m = t_p − M·t_c.
  const Mat3 m3 = mulTransposed(proj.R, cam.R);
  const Vec3 mt = mul(m3, cam.t);
  const Vec3 m{proj.t[0] - mt[0], proj.t[1] - mt[1], proj.t[2] - mt[2]};
  const double a = -dot(n0, m);
  const double b = m[2];

  const auto pixels = static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height);
  std::vector<double> c(pixels, 0.0);
  std::vector<double> d(pixels, 0.0);
  TriangulationTables t;
  t.width = cam.width;
  t.height = cam.height;
  t.sense.assign(pixels, 0);
  double largest = 0.0;
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const auto n =
          lens::undistort(cam.dist, {(x - cam.cx()) / cam.fx(), (y - cam.cy()) / cam.fy()});
      if (!n) {
        continue;
      }
      const Vec3 mr = mul(m3, {n->x, n->y, 1.0});
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(cam.width) +
                            static_cast<std::size_t>(x);
      c[i] = dot(n0, mr);
      d[i] = -mr[2];
      const double sense = b * c[i] - a * d[i];
      t.sense[i] = static_cast<std::int8_t>(sense > 0 ? 1 : (sense < 0 ? -1 : 0));
      largest = std::max({largest, std::abs(c[i]), std::abs(d[i])});
    }
  }
  if (!(largest > 0.0)) {
    return std::unexpected("triangulation: camera '" + cam.id + "' has no usable pixel ray");
  }
  // 2^k: the largest that keeps |C'|, |D'| ≤ 2^30 and the numerator within 2^62.
  int k = static_cast<int>(std::floor(std::log2(std::ldexp(1.0, 30) / largest)));
  const double sMax = 198.0 * kStripeOne;
  const auto numeratorBound = [&](int e) {
    return std::abs(std::ldexp(a, e) * kStripeOne / depthUnitM) +
           std::abs(std::ldexp(b, e) / depthUnitM) * sMax;
  };
  while (numeratorBound(k) >= std::ldexp(1.0, 62)) {
    --k;
  }
  t.numeratorBase = std::llround(std::ldexp(a, k) * kStripeOne / depthUnitM);
  t.numeratorSlope = std::llround(std::ldexp(b, k) / depthUnitM);
  t.denominatorBase.resize(pixels);
  t.denominatorSlope.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    t.denominatorBase[i] = static_cast<std::int32_t>(std::lround(std::ldexp(c[i], k)));
    t.denominatorSlope[i] = static_cast<std::int32_t>(std::lround(std::ldexp(d[i], k)));
  }
  return t;
}

}  // namespace smx::algo
