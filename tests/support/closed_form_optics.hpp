#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>

#include "smx/algo/rig.hpp"

// The rig's optics written out from their definitions (docs/rig-format.md, docs/pattern.md), as
// an independent truth for tests of the code that implements them (algo::lens, the renderer).
namespace smx::test {

inline Eigen::Matrix3d rotationOf(const algo::DeviceModel& m) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.R.data());
}

inline Eigen::Vector3d toDevice(const algo::DeviceModel& m, const Eigen::Vector3d& X) {
  return rotationOf(m) * X + Eigen::Vector3d(m.t[0], m.t[1], m.t[2]);
}

inline Eigen::Vector3d centreOf(const algo::DeviceModel& m) {
  return -rotationOf(m).transpose() * Eigen::Vector3d(m.t[0], m.t[1], m.t[2]);
}

// Pinhole K plus Brown–Conrady (k1 k2 p1 p2 k3), as cv::projectPoints; `distort` false drops the
// distortion. nullopt behind the device.
inline std::optional<std::array<double, 2>> projectPoint(const algo::DeviceModel& m,
                                                         const Eigen::Vector3d& X,
                                                         bool distort = true) {
  const Eigen::Vector3d x = toDevice(m, X);
  if (!(x.z() > 0.0)) {
    return std::nullopt;
  }
  const double a = x.x() / x.z();
  const double b = x.y() / x.z();
  const auto [k1, k2, p1, p2, k3] = distort ? m.dist : std::array<double, 5>{};
  const double r2 = a * a + b * b;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
  const double xd = a * radial + 2.0 * p1 * a * b + p2 * (r2 + 2.0 * a * a);
  const double yd = b * radial + p1 * (r2 + 2.0 * b * b) + 2.0 * p2 * a * b;
  return std::array<double, 2>{m.K[0] * xd + m.K[2], m.K[4] * yd + m.K[5]};
}

// docs/pattern.md: the stripe coordinate at projector pixel (u, v).
inline double stripeFormula(const algo::Projector& p, double u, double v) {
  const double a = p.pattern.angleDeg * std::numbers::pi / 180.0;
  return ((u - (p.width - 1) / 2.0) * std::cos(a) + (v - (p.height - 1) / 2.0) * std::sin(a) -
          p.pattern.offsetPx) /
             p.pattern.stripePx +
         99.0;
}

}  // namespace smx::test
