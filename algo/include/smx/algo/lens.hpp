#pragma once

#include <array>
#include <optional>

#include "smx/algo/rig.hpp"

// The OpenCV pinhole + (k1, k2, p1, p2, k3) lens model of rig.json devices. Init-time and host
// code (ray tables, simulator); double precision.
namespace smx::algo::lens {

struct Point2 {
  double x = 0.0;
  double y = 0.0;
};

using Point3 = std::array<double, 3>;

struct Ray {
  Point3 origin;     // device centre, world coordinates
  Point3 direction;  // unit length, world coordinates
};

// Normalised undistorted coordinates → distorted ones.
[[nodiscard]] Point2 distort(const std::array<double, 5>& dist, Point2 undistorted);

// Inverse of distort() by Newton's method; nullopt when it does not converge to 1e-12 (far
// outside the range the model is valid for).
[[nodiscard]] std::optional<Point2> undistort(const std::array<double, 5>& dist, Point2 distorted);

// World point → device frame: x_dev = R·X + t.
[[nodiscard]] Point3 toDevice(const DeviceModel& device, const Point3& world);

// Device frame → world: X = Rᵀ·(x_dev − t).
[[nodiscard]] Point3 toWorld(const DeviceModel& device, const Point3& local);

// Pixel coordinates and z (depth along the device's optical axis) → the point in the device
// frame, z·(x_n, y_n, 1) with (x_n, y_n) undistorted; nullopt if the distortion cannot be
// inverted there. How a range image becomes points.
[[nodiscard]] std::optional<Point3> devicePoint(const DeviceModel& device, Point2 pixel, double z);

// Device centre in world coordinates: −Rᵀ·t.
[[nodiscard]] Point3 centre(const DeviceModel& device);

// World point → pixel coordinates (distortion applied); nullopt behind the device (z ≤ 0).
[[nodiscard]] std::optional<Point2> project(const DeviceModel& device, const Point3& world);

// Pixel coordinates → the world ray through them (distortion removed); nullopt if the
// distortion cannot be inverted there.
[[nodiscard]] std::optional<Ray> pixelRay(const DeviceModel& device, Point2 pixel);

}  // namespace smx::algo::lens
