#include "smx/algo/lens.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace smx::algo::lens {
namespace {

// A camera 0.3 m left of the origin, turned 20° about y to look at (0, 0, 0.9), with distortion.
DeviceModel makeDevice(std::array<double, 5> dist) {
  DeviceModel d;
  d.width = 640;
  d.height = 480;
  d.K = {800, 0, 320.5, 0, 810, 240.25, 0, 0, 1};
  d.dist = dist;
  const double a = 20.0 * std::numbers::pi / 180.0;
  d.R = {std::cos(a), 0, -std::sin(a), 0, 1, 0, std::sin(a), 0, std::cos(a)};
  const Point3 c = {-0.3, 0.02, 0.0};
  for (int i = 0; i < 3; ++i) {
    d.t[static_cast<std::size_t>(i)] = -(d.R[static_cast<std::size_t>(3 * i)] * c[0] +
                                         d.R[static_cast<std::size_t>(3 * i + 1)] * c[1] +
                                         d.R[static_cast<std::size_t>(3 * i + 2)] * c[2]);
  }
  return d;
}

TEST(Lens, DistortionMatchesTheOpenCvFormulaAtAHandComputedPoint) {
  // x = 0.2, y = -0.1: r² = 0.05; radial = 1 + 0.05·(-0.3) + 0.0025·0.1 + 0.000125·0.01
  const std::array<double, 5> dist = {-0.3, 0.1, 0.001, -0.002, 0.01};
  const Point2 d = distort(dist, {0.2, -0.1});
  const double radial = 1.0 - 0.015 + 0.00025 + 0.00000125;
  EXPECT_NEAR(d.x, 0.2 * radial + 2 * 0.001 * 0.2 * -0.1 + -0.002 * (0.05 + 2 * 0.04), 1e-15);
  EXPECT_NEAR(d.y, -0.1 * radial + 0.001 * (0.05 + 2 * 0.01) + 2 * -0.002 * 0.2 * -0.1, 1e-15);
}

TEST(Lens, UndistortInvertsDistortAcrossTheImage) {
  const std::array<double, 5> dist = {-0.25, 0.08, 0.0008, -0.0005, -0.01};
  for (double x = -0.45; x <= 0.45; x += 0.05) {
    for (double y = -0.35; y <= 0.35; y += 0.05) {
      const auto u = undistort(dist, distort(dist, {x, y}));
      ASSERT_TRUE(u.has_value()) << x << "," << y;
      EXPECT_NEAR(u->x, x, 1e-11);
      EXPECT_NEAR(u->y, y, 1e-11);
    }
  }
}

TEST(Lens, PixelRayAndProjectAreInverse) {
  const auto d = makeDevice({-0.2, 0.05, 0.001, 0.0005, 0.0});
  for (double px = 0; px < 640; px += 63.7) {
    for (double py = 0; py < 480; py += 47.3) {
      const auto ray = pixelRay(d, {px, py});
      ASSERT_TRUE(ray.has_value());
      const double s = 0.7 + px / 1000.0;
      const Point3 p = {ray->origin[0] + s * ray->direction[0],
                        ray->origin[1] + s * ray->direction[1],
                        ray->origin[2] + s * ray->direction[2]};
      const auto back = project(d, p);
      ASSERT_TRUE(back.has_value());
      EXPECT_NEAR(back->x, px, 1e-8);
      EXPECT_NEAR(back->y, py, 1e-8);
    }
  }
}

// A range image's pixel and depth back to a world point: it lies at that depth in the device
// frame and projects onto the same pixel.
TEST(Lens, DevicePointAtADepthProjectsBackToItsPixel) {
  const auto d = makeDevice({-0.2, 0.05, 0.001, 0.0005, 0.0});
  for (double px = 0; px < 640; px += 63.7) {
    for (double py = 0; py < 480; py += 47.3) {
      const double z = 0.6 + py / 1000.0;
      const auto local = devicePoint(d, {px, py}, z);
      ASSERT_TRUE(local.has_value());
      EXPECT_DOUBLE_EQ((*local)[2], z);
      const Point3 world = toWorld(d, *local);
      const Point3 again = toDevice(d, world);
      for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_NEAR(again[i], (*local)[i], 1e-12);
      }
      const auto back = project(d, world);
      ASSERT_TRUE(back.has_value());
      EXPECT_NEAR(back->x, px, 1e-8);
      EXPECT_NEAR(back->y, py, 1e-8);
    }
  }
}

TEST(Lens, CentreAndProjectionOfAKnownPoint) {
  const auto d = makeDevice({0, 0, 0, 0, 0});
  const auto c = centre(d);
  EXPECT_NEAR(c[0], -0.3, 1e-15);
  EXPECT_NEAR(c[1], 0.02, 1e-15);
  EXPECT_NEAR(c[2], 0.0, 1e-15);
  // The point straight ahead along the device's optical axis lands on the principal point.
  const double a = 20.0 * std::numbers::pi / 180.0;
  const Point3 ahead = {-0.3 + std::sin(a), 0.02, std::cos(a)};
  const auto p = project(d, ahead);
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x, 320.5, 1e-9);
  EXPECT_NEAR(p->y, 240.25, 1e-9);
  EXPECT_FALSE(project(d, {-0.3 - std::sin(a), 0.02, -std::cos(a)}).has_value());  // behind
}

}  // namespace
}  // namespace smx::algo::lens
