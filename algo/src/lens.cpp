#include "smx/algo/lens.hpp"

#include <cmath>

namespace smx::algo::lens {

Point2 distort(const std::array<double, 5>& dist, Point2 undistorted) {
  const auto [k1, k2, p1, p2, k3] = dist;
  const auto [x, y] = undistorted;
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

std::optional<Point2> undistort(const std::array<double, 5>& dist, Point2 distorted) {
  const auto [k1, k2, p1, p2, k3] = dist;
  Point2 p = distorted;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Point2 d = distort(dist, p);
    const double ex = d.x - distorted.x;
    const double ey = d.y - distorted.y;
    if (std::abs(ex) < 1e-12 && std::abs(ey) < 1e-12) {
      return p;
    }
    // Jacobian of distort() at p.
    const double r2 = p.x * p.x + p.y * p.y;
    const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dRadial = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2);  // d radial / d r2
    const double jxx = radial + 2.0 * p.x * p.x * dRadial + 2.0 * p1 * p.y + 6.0 * p2 * p.x;
    const double jxy = 2.0 * p.x * p.y * dRadial + 2.0 * p1 * p.x + 2.0 * p2 * p.y;
    const double jyx = 2.0 * p.x * p.y * dRadial + 2.0 * p1 * p.x + 2.0 * p2 * p.y;
    const double jyy = radial + 2.0 * p.y * p.y * dRadial + 6.0 * p1 * p.y + 2.0 * p2 * p.x;
    const double det = jxx * jyy - jxy * jyx;
    if (!(std::abs(det) > 1e-12)) {
      return std::nullopt;
    }
    p.x -= (jyy * ex - jxy * ey) / det;
    p.y -= (-jyx * ex + jxx * ey) / det;
  }
  return std::nullopt;
}

Point3 toDevice(const DeviceModel& d, const Point3& w) {
  const auto& rot = d.R;
  return {rot[0] * w[0] + rot[1] * w[1] + rot[2] * w[2] + d.t[0],
          rot[3] * w[0] + rot[4] * w[1] + rot[5] * w[2] + d.t[1],
          rot[6] * w[0] + rot[7] * w[1] + rot[8] * w[2] + d.t[2]};
}

Point3 centre(const DeviceModel& d) {
  const auto& rot = d.R;
  const auto& t = d.t;
  return {-(rot[0] * t[0] + rot[3] * t[1] + rot[6] * t[2]),
          -(rot[1] * t[0] + rot[4] * t[1] + rot[7] * t[2]),
          -(rot[2] * t[0] + rot[5] * t[1] + rot[8] * t[2])};
}

std::optional<Point2> project(const DeviceModel& d, const Point3& world) {
  const Point3 x = toDevice(d, world);
  if (!(x[2] > 0.0)) {
    return std::nullopt;
  }
  const Point2 xd = distort(d.dist, {x[0] / x[2], x[1] / x[2]});
  return Point2{d.fx() * xd.x + d.cx(), d.fy() * xd.y + d.cy()};
}

Point3 toWorld(const DeviceModel& d, const Point3& local) {
  const auto& r = d.R;
  const Point3 c = {local[0] - d.t[0], local[1] - d.t[1], local[2] - d.t[2]};
  return {r[0] * c[0] + r[3] * c[1] + r[6] * c[2], r[1] * c[0] + r[4] * c[1] + r[7] * c[2],
          r[2] * c[0] + r[5] * c[1] + r[8] * c[2]};
}

std::optional<Point3> devicePoint(const DeviceModel& d, Point2 pixel, double z) {
  const auto xn = undistort(d.dist, {(pixel.x - d.cx()) / d.fx(), (pixel.y - d.cy()) / d.fy()});
  if (!xn) {
    return std::nullopt;
  }
  return Point3{xn->x * z, xn->y * z, z};
}

std::optional<Ray> pixelRay(const DeviceModel& d, Point2 pixel) {
  const auto xn = undistort(d.dist, {(pixel.x - d.cx()) / d.fx(), (pixel.y - d.cy()) / d.fy()});
  if (!xn) {
    return std::nullopt;
  }
  const auto& rot = d.R;
  // Direction Rᵀ·(x, y, 1), normalised.
  Point3 dir = {rot[0] * xn->x + rot[3] * xn->y + rot[6], rot[1] * xn->x + rot[4] * xn->y + rot[7],
                rot[2] * xn->x + rot[5] * xn->y + rot[8]};
  const double n = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  for (auto& c : dir) {
    c /= n;
  }
  return Ray{centre(d), dir};
}

}  // namespace smx::algo::lens
