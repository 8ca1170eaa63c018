#include "smx/health/drift.hpp"

#include <cmath>
#include <cstddef>
#include <numbers>

#include "smx/algo/lens.hpp"

namespace smx::health {

namespace {

using Mat3 = std::array<double, 9>;
using Vec3 = std::array<double, 3>;

// Rodrigues: the rotation matrix of a rotation vector.
Mat3 rotation(const Vec3& w) {
  const double angle = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  if (angle == 0) {
    return {1, 0, 0, 0, 1, 0, 0, 0, 1};
  }
  const Vec3 k{w[0] / angle, w[1] / angle, w[2] / angle};
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  const double v = 1 - c;
  return {c + k[0] * k[0] * v,        k[0] * k[1] * v - k[2] * s, k[0] * k[2] * v + k[1] * s,
          k[1] * k[0] * v + k[2] * s, c + k[1] * k[1] * v,        k[1] * k[2] * v - k[0] * s,
          k[2] * k[0] * v - k[1] * s, k[2] * k[1] * v + k[0] * s, c + k[2] * k[2] * v};
}

Mat3 times(const Mat3& a, const Mat3& b) {
  Mat3 m{};
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c) {
      for (std::size_t k = 0; k < 3; ++k) {
        m[r * 3 + c] += a[r * 3 + k] * b[k * 3 + c];
      }
    }
  }
  return m;
}

Vec3 times(const Mat3& a, const Vec3& v) {
  return {a[0] * v[0] + a[1] * v[1] + a[2] * v[2], a[3] * v[0] + a[4] * v[1] + a[5] * v[2],
          a[6] * v[0] + a[7] * v[1] + a[8] * v[2]};
}

Vec3 unit(const Vec3& v) {
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return {v[0] / n, v[1] / n, v[2] / n};
}

Vec3 scaled(const Vec3& v, double s) {
  return {v[0] * s, v[1] * s, v[2] * s};
}

}  // namespace

algo::Rig withDrift(const algo::Rig& rig, int projector, const Drift& drift) {
  algo::Rig moved = rig;
  algo::Projector& p = moved.projectors.at(static_cast<std::size_t>(projector));
  // x_dev' = Q·(x_dev − shift): the device frame turned by Q about the moved centre.
  const Mat3 q = rotation(drift.rotationRad);
  const Vec3 t{p.t[0] - drift.shiftM[0], p.t[1] - drift.shiftM[1], p.t[2] - drift.shiftM[2]};
  p.R = times(q, p.R);
  p.t = times(q, t);
  return moved;
}

std::vector<NamedDrift> specifiedDrifts(const algo::Rig& rig, int projector, int camera) {
  constexpr double kShiftM = 0.001;
  constexpr double kTurnRad = 0.2 * std::numbers::pi / 180.0;
  const algo::Projector& p = rig.projectors.at(static_cast<std::size_t>(projector));
  const algo::Camera& c = rig.cameras.at(static_cast<std::size_t>(camera));
  // The baseline in the projector frame: towards the camera's centre.
  const Vec3 baseline = unit(algo::lens::toDevice(p, algo::lens::centre(c)));
  // Perpendicular to it towards the scene: the part of the optical axis across the baseline.
  const Vec3 perpendicular =
      unit({-baseline[2] * baseline[0], -baseline[2] * baseline[1], 1 - baseline[2] * baseline[2]});
  const double a = p.pattern.angleDeg * std::numbers::pi / 180.0;
  const Vec3 stripeAxis{-std::sin(a), std::cos(a), 0};
  return {
      {"1 mm along the baseline", {scaled(baseline, kShiftM), {}}},
      {"1 mm perpendicular to the baseline", {scaled(perpendicular, kShiftM), {}}},
      {"0.2° about the stripe axis", {{}, scaled(stripeAxis, kTurnRad)}},
      {"0.2° about the optical axis", {{}, {0, 0, kTurnRad}}},
  };
}

}  // namespace smx::health

namespace smx::health {

std::vector<NamedDrift> limitDrifts(const algo::Rig& rig, int projector) {
  constexpr double kShiftM = 0.001;
  const double a = rig.projectors.at(static_cast<std::size_t>(projector)).pattern.angleDeg *
                   std::numbers::pi / 180.0;
  return {
      {"1 mm along the optical axis", {{0, 0, kShiftM}, {}}},
      {"1 mm along the stripes", {{-std::sin(a) * kShiftM, std::cos(a) * kShiftM, 0}, {}}},
  };
}

}  // namespace smx::health
