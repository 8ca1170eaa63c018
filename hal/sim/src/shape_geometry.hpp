#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <variant>

#include "smx/sim/scene.hpp"

// Exact (double) geometry of the analytic shapes of scene.hpp, in object-local coordinates. Each
// shape is split into surfaces that Embree sees as user primitives: a plane is 1, a box its 6
// faces, a sphere 1, a cylinder its side plus 2 caps. Knowing the surface (Embree's primID), the
// renderer re-intersects the double camera ray with it (refineSurface) for exact ground truth.
namespace smx::sim::detail {

struct LocalHit {
  double t = 0.0;
  Vec3 normal = Vec3::UnitZ();  // unit, local; outward for closed shapes, +z for a plane
};

struct LocalBox {
  Vec3 centre = Vec3::Zero();
  Vec3 halfSize = Vec3::Zero();
};

// One surface: a flat face (the plane x[axis] = offset, bounded by a rectangle or a disc in the
// other two axes), a sphere, or a cylinder side (axis local y).
struct Surface {
  enum class Kind { kFlat, kSphere, kCylinderSide };
  Kind kind = Kind::kFlat;
  int axis = 2;
  double offset = 0.0;
  std::array<double, 2> half{};  // flat: half extents along axes (axis+1)%3, (axis+2)%3
  bool disc = false;             // flat: bounded by x1² + x2² ≤ radius² instead
  double radius = 0.0;
  double halfHeight = 0.0;  // cylinder side: |y| ≤ halfHeight
};

[[nodiscard]] inline int surfaceCount(const Shape& shape) {
  struct Count {
    int operator()(const Plane&) const { return 1; }
    int operator()(const Box&) const { return 6; }
    int operator()(const Sphere&) const { return 1; }
    int operator()(const Cylinder& c) const { return c.capped ? 3 : 1; }
    int operator()(const Mesh&) const { return 0; }
  };
  return std::visit(Count{}, shape);
}

[[nodiscard]] inline Surface surfaceOf(const Shape& shape, int index) {
  Surface s;
  if (const auto* plane = std::get_if<Plane>(&shape)) {
    s.half = {plane->widthM / 2.0, plane->heightM / 2.0};
  } else if (const auto* box = std::get_if<Box>(&shape)) {
    // Faces −x, +x, −y, +y, −z, +z.
    s.axis = index / 2;
    s.offset = (index % 2 == 0 ? -0.5 : 0.5) * box->sizeM[s.axis];
    s.half = {box->sizeM[(s.axis + 1) % 3] / 2.0, box->sizeM[(s.axis + 2) % 3] / 2.0};
  } else if (const auto* sphere = std::get_if<Sphere>(&shape)) {
    s.kind = Surface::Kind::kSphere;
    s.radius = sphere->radiusM;
  } else if (const auto* cylinder = std::get_if<Cylinder>(&shape)) {
    s.radius = cylinder->radiusM;
    s.halfHeight = cylinder->heightM / 2.0;
    if (index == 0) {
      s.kind = Surface::Kind::kCylinderSide;
    } else {  // caps at y = −h/2 (1) and y = +h/2 (2)
      s.axis = 1;
      s.offset = index == 1 ? -s.halfHeight : s.halfHeight;
      s.disc = true;
    }
  }
  return s;
}

// Local axis-aligned bounds of a surface.
[[nodiscard]] inline LocalBox surfaceBounds(const Surface& s) {
  LocalBox b;
  switch (s.kind) {
    case Surface::Kind::kFlat: {
      const auto a1 = static_cast<Eigen::Index>((s.axis + 1) % 3);
      const auto a2 = static_cast<Eigen::Index>((s.axis + 2) % 3);
      b.centre[s.axis] = s.offset;
      b.halfSize[a1] = s.disc ? s.radius : s.half[0];
      b.halfSize[a2] = s.disc ? s.radius : s.half[1];
      break;
    }
    case Surface::Kind::kSphere:
      b.halfSize = Vec3::Constant(s.radius);
      break;
    case Surface::Kind::kCylinderSide:
      b.halfSize = {s.radius, s.halfHeight, s.radius};
      break;
  }
  return b;
}

// Roots of a·t² + 2b·t + c = 0 for a > 0 and disc = b² − a·c ≥ 0, without cancellation.
[[nodiscard]] inline std::array<double, 2> quadraticRoots(double a, double b, double c,
                                                          double disc) {
  const double q = -(b + std::copysign(std::sqrt(disc), b));
  if (q == 0.0) {
    return {0.0, 0.0};  // b = 0 and disc = 0 imply c = 0: a double root at 0
  }
  const double t0 = q / a;
  const double t1 = c / q;
  return {std::min(t0, t1), std::max(t0, t1)};
}

[[nodiscard]] inline Vec3 surfaceNormal(const Surface& s, const Vec3& p) {
  switch (s.kind) {
    case Surface::Kind::kFlat: {
      Vec3 n = Vec3::Zero();
      n[s.axis] = s.offset < 0.0 ? -1.0 : 1.0;
      return n;
    }
    case Surface::Kind::kSphere:
      return p.normalized();
    case Surface::Kind::kCylinderSide:
      return Vec3(p.x(), 0.0, p.z()).normalized();
  }
  return Vec3::UnitZ();
}

[[nodiscard]] inline bool insideFace(const Surface& s, const Vec3& p) {
  const double x1 = p[(s.axis + 1) % 3];
  const double x2 = p[(s.axis + 2) % 3];
  if (s.disc) {
    return x1 * x1 + x2 * x2 <= s.radius * s.radius;
  }
  return std::abs(x1) <= s.half[0] && std::abs(x2) <= s.half[1];
}

// The unbounded surface's crossings of the ray o + t·d (0, 1 or 2 values of t; a flat face and a
// ray parallel to it give none). With `clampTangent`, a ray that misses a curved surface by
// rounding (discriminant slightly below 0) is treated as tangent.
struct Crossings {
  std::array<double, 2> t{};
  int count = 0;
};

[[nodiscard]] inline Crossings crossings(const Surface& s, const Vec3& o, const Vec3& d,
                                         bool clampTangent) {
  Crossings out;
  double a = 0.0;
  double b = 0.0;
  double c = 0.0;
  switch (s.kind) {
    case Surface::Kind::kFlat:
      if (d[s.axis] != 0.0) {
        out.t[0] = (s.offset - o[s.axis]) / d[s.axis];
        out.count = 1;
      }
      return out;
    case Surface::Kind::kSphere:
      a = d.squaredNorm();
      b = o.dot(d);
      c = o.squaredNorm() - s.radius * s.radius;
      break;
    case Surface::Kind::kCylinderSide:
      a = d.x() * d.x() + d.z() * d.z();
      b = o.x() * d.x() + o.z() * d.z();
      c = o.x() * o.x() + o.z() * o.z() - s.radius * s.radius;
      break;
  }
  if (!(a > 0.0)) {
    return out;  // parallel to the cylinder axis (or a zero direction)
  }
  double disc = b * b - a * c;
  if (disc < 0.0) {
    if (!clampTangent) {
      return out;
    }
    disc = 0.0;
  }
  out.t = quadraticRoots(a, b, c, disc);
  out.count = 2;
  return out;
}

// Nearest crossing of the bounded surface with t in (tMin, tMax].
[[nodiscard]] inline std::optional<LocalHit> intersectSurface(const Surface& s, const Vec3& o,
                                                              const Vec3& d, double tMin,
                                                              double tMax) {
  const Crossings x = crossings(s, o, d, false);
  for (int i = 0; i < x.count; ++i) {
    const double t = x.t[static_cast<std::size_t>(i)];
    const bool inRange = t > tMin && t <= tMax;  // false for NaN
    if (!inRange) {
      continue;
    }
    const Vec3 p = o + t * d;
    const bool inside = s.kind == Surface::Kind::kFlat           ? insideFace(s, p)
                        : s.kind == Surface::Kind::kCylinderSide ? std::abs(p.y()) <= s.halfHeight
                                                                 : true;
    if (inside) {
      return LocalHit{t, surfaceNormal(s, p)};
    }
  }
  return std::nullopt;
}

// The crossing of the unbounded surface nearest to tHint (where Embree found the surface): the
// exact hit in double. Falls back to tHint where the ray is parallel to a face.
[[nodiscard]] inline LocalHit refineSurface(const Surface& s, const Vec3& o, const Vec3& d,
                                            double tHint) {
  const Crossings x = crossings(s, o, d, true);
  double t = tHint;
  double best = INFINITY;
  for (int i = 0; i < x.count; ++i) {
    const double ti = x.t[static_cast<std::size_t>(i)];
    if (std::abs(ti - tHint) < best) {
      best = std::abs(ti - tHint);
      t = ti;
    }
  }
  return LocalHit{t, surfaceNormal(s, o + t * d)};
}

}  // namespace smx::sim::detail
