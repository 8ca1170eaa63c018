#pragma once

#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <numbers>

#include "smx/algo/rig.hpp"
#include "smx/algo/stripe_code.hpp"

// The projector as the stripe samples see it, shared by the projector fit and the joint
// refinement: world point → stripe coordinate, in a form Ceres differentiates.
namespace smx::calib::detail {

// What the samples do not determine, kept from the nominal projector.
struct ProjectorConstants {
  double fx = 1.0;  // the fit scales both focal lengths by one factor
  double fy = 1.0;
  double cx = 0.0;  // the fit moves the principal point along the encoding axis only
  double cy = 0.0;
  double cosA = 1.0;
  double sinA = 0.0;
  double patternCu = 0.0;  // the pattern's centre, projector px
  double patternCv = 0.0;
  double offsetPx = 0.0;
  double stripePx = 1.0;
  double k3 = 0.0;

  explicit ProjectorConstants(const algo::Projector& nominal)
      : fx(nominal.fx()),
        fy(nominal.fy()),
        cx(nominal.cx()),
        cy(nominal.cy()),
        cosA(std::cos(nominal.pattern.angleDeg * std::numbers::pi / 180.0)),
        sinA(std::sin(nominal.pattern.angleDeg * std::numbers::pi / 180.0)),
        patternCu((nominal.width - 1) / 2.0),
        patternCv((nominal.height - 1) / 2.0),
        offsetPx(nominal.pattern.offsetPx),
        stripePx(nominal.pattern.stripePx),
        k3(nominal.dist[4]) {}
};

// The fitted parameters, one Ceres block each.
struct ProjectorParams {
  std::array<double, 3> rotation{};    // angle-axis, world → device
  std::array<double, 3> centre{};      // world
  std::array<double, 2> intrinsics{};  // focal scale, principal point shift along the axis (px)
  std::array<double, 4> lens{};        // k1 k2 p1 p2
};

[[nodiscard]] inline ProjectorParams paramsOf(const algo::Projector& nominal) {
  const Eigen::Matrix3d rot =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(nominal.R.data());
  const Eigen::Vector3d c =
      -rot.transpose() * Eigen::Vector3d(nominal.t[0], nominal.t[1], nominal.t[2]);
  const Eigen::AngleAxisd aa(rot);
  const Eigen::Vector3d rv = aa.axis() * aa.angle();
  return {.rotation = {rv[0], rv[1], rv[2]},
          .centre = {c[0], c[1], c[2]},
          .intrinsics = {1.0, 0.0},
          .lens = {nominal.dist[0], nominal.dist[1], nominal.dist[2], nominal.dist[3]}};
}

[[nodiscard]] inline algo::Projector projectorOf(const algo::Projector& nominal,
                                                 const ProjectorConstants& k,
                                                 const ProjectorParams& p) {
  algo::Projector out = nominal;
  const Eigen::Vector3d rv(p.rotation[0], p.rotation[1], p.rotation[2]);
  const double angle = rv.norm();
  const Eigen::Matrix3d rot = angle > 0 ? Eigen::AngleAxisd(angle, rv / angle).toRotationMatrix()
                                        : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d t = -rot * Eigen::Vector3d(p.centre[0], p.centre[1], p.centre[2]);
  for (int i = 0; i < 9; ++i) {
    out.R[static_cast<std::size_t>(i)] = rot(i / 3, i % 3);
  }
  out.t = {t[0], t[1], t[2]};
  const double scale = p.intrinsics[0];
  const double shift = p.intrinsics[1];
  out.K = {scale * k.fx, 0, k.cx + shift * k.cosA, 0, scale * k.fy, k.cy + shift * k.sinA, 0, 0, 1};
  out.dist = {p.lens[0], p.lens[1], p.lens[2], p.lens[3], k.k3};
  return out;
}

// The stripe coordinate (algo::stripeCoordinate) the projector casts on the world point.
template <class T>
T stripeAt(const ProjectorConstants& k, const T* rotation, const T* centre, const T* intrinsics,
           const T* lens, const T* world) {
  const T rel[3] = {world[0] - centre[0], world[1] - centre[1], world[2] - centre[2]};
  T dev[3];
  ceres::AngleAxisRotatePoint(rotation, rel, dev);
  const T x = dev[0] / dev[2];
  const T y = dev[1] / dev[2];
  const T r2 = x * x + y * y;
  const T radial =
      static_cast<T>(1) + lens[0] * r2 + lens[1] * r2 * r2 + static_cast<T>(k.k3) * r2 * r2 * r2;
  const T xd =
      x * radial + static_cast<T>(2) * lens[2] * x * y + lens[3] * (r2 + static_cast<T>(2) * x * x);
  const T yd =
      y * radial + lens[2] * (r2 + static_cast<T>(2) * y * y) + static_cast<T>(2) * lens[3] * x * y;
  const T u = intrinsics[0] * static_cast<T>(k.fx) * xd + static_cast<T>(k.cx) +
              intrinsics[1] * static_cast<T>(k.cosA);
  const T v = intrinsics[0] * static_cast<T>(k.fy) * yd + static_cast<T>(k.cy) +
              intrinsics[1] * static_cast<T>(k.sinA);
  const T along = (u - static_cast<T>(k.patternCu)) * static_cast<T>(k.cosA) +
                  (v - static_cast<T>(k.patternCv)) * static_cast<T>(k.sinA) -
                  static_cast<T>(k.offsetPx);
  return along / static_cast<T>(k.stripePx) + static_cast<T>(algo::stripe::kStripes / 2.0);
}

// The centre along the stripes' direction is not observed (every boundary surface contains
// that line through the centre): a weak prior keeps it at the nominal.
struct CentrePrior {
  static constexpr double kSigmaM = 0.01;
  Eigen::Vector3d nominal;
  Eigen::Vector3d direction;  // unit, world

  CentrePrior(const algo::Projector& p, const ProjectorConstants& k) {
    const Eigen::Matrix3d rot =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(p.R.data());
    nominal = -rot.transpose() * Eigen::Vector3d(p.t[0], p.t[1], p.t[2]);
    direction = (rot.transpose() * Eigen::Vector3d(-k.sinA, k.cosA, 0.0)).normalized();
  }

  template <class T>
  bool operator()(const T* centre, T* residual) const {
    T along = static_cast<T>(0);
    for (int i = 0; i < 3; ++i) {
      along += (centre[i] - static_cast<T>(nominal[i])) * static_cast<T>(direction[i]);
    }
    residual[0] = along / static_cast<T>(kSigmaM);
    return true;
  }
};

// A projector lens's distortion is of a known order (|k1| ≲ 0.1), and samples from a board near
// the image centre barely constrain the higher terms, which then extrapolate wildly towards the
// image edges: a weak prior at the nominal lens keeps what the data does not determine there.
struct LensPrior {
  static constexpr std::array<double, 4> kSigma = {0.05, 0.02, 0.002, 0.002};  // k1 k2 p1 p2
  std::array<double, 4> nominal{};
  double scale = 1.0;  // the residual unit of the problem it joins (1: residuals in sigmas)

  template <class T>
  bool operator()(const T* lens, T* residual) const {
    for (std::size_t i = 0; i < 4; ++i) {
      residual[i] = (lens[i] - static_cast<T>(nominal[i])) / static_cast<T>(kSigma[i]) *
                    static_cast<T>(scale);
    }
    return true;
  }
};

}  // namespace smx::calib::detail
