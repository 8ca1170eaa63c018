// What a view gives the model: the table's volume and the pixels dropped at edges and grazing
// incidence, on range images of planes computed in closed form for a pinhole camera.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "smx/scan/range_clean.hpp"
#include "smx/scan/table_crop.hpp"

namespace smx::scan {
namespace {

constexpr int kWidth = 160;
constexpr int kHeight = 120;
constexpr double kUnitM = 1e-4;

algo::Rig pinholeRig() {
  algo::Camera camera;
  camera.id = "cam0";
  camera.width = kWidth;
  camera.height = kHeight;
  camera.K = {150, 0, (kWidth - 1) / 2.0, 0, 150, (kHeight - 1) / 2.0, 0, 0, 1};
  camera.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  algo::Rig rig;
  rig.cameras.push_back(camera);
  return rig;
}

// The plane n·X = d seen by the pinhole camera: z = d / (n · (x_n, y_n, 1)).
RangeView planeView(const Eigen::Vector3d& normal, double d) {
  const algo::Camera c = pinholeRig().cameras[0];
  CameraRange range{.width = kWidth, .height = kHeight, .depth = {}, .colour = {}};
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const Eigen::Vector3d ray((x - c.cx()) / c.fx(), (y - c.cy()) / c.fy(), 1.0);
      const double z = d / normal.dot(ray);
      range.depth.push_back(static_cast<std::uint16_t>(std::lround(z / kUnitM)));
    }
  }
  RangeView view;
  view.id = "00000";
  view.depthUnitM = kUnitM;
  view.cameras.push_back(std::move(range));
  return view;
}

std::uint16_t depthAt(const RangeView& v, int x, int y) {
  return v.cameras[0].depth[static_cast<std::size_t>(y) * kWidth + static_cast<std::size_t>(x)];
}

// A plane turned by `deg` about the camera's y axis, 0.8 m away on the optical axis.
RangeView tiltedPlane(double deg) {
  const double a = deg * std::numbers::pi / 180.0;
  const Eigen::Vector3d n(std::sin(a), 0.0, std::cos(a));
  return planeView(n, n.dot(Eigen::Vector3d(0, 0, 0.8)));
}

TEST(RangeClean, AFacingPlaneKeepsEveryInnerPixel) {
  RangeView view = tiltedPlane(0);
  cleanForFusion(view, pinholeRig());
  EXPECT_EQ(depthAt(view, 0, 0), 0);  // the image's rim has no neighbours to judge by
  for (int y = 1; y + 1 < kHeight; ++y) {
    for (int x = 1; x + 1 < kWidth; ++x) {
      ASSERT_NE(depthAt(view, x, y), 0) << x << "," << y;
    }
  }
}

TEST(RangeClean, PixelsWithinTwoOfAHoleGoThoseBeyondStay) {
  RangeView view = tiltedPlane(20);
  for (int y = 50; y < 60; ++y) {
    for (int x = 70; x < 80; ++x) {
      view.cameras[0].depth[static_cast<std::size_t>(y) * kWidth + static_cast<std::size_t>(x)] = 0;
    }
  }
  cleanForFusion(view, pinholeRig());
  EXPECT_EQ(depthAt(view, 68, 55), 0);  // 2 px left of the hole
  EXPECT_EQ(depthAt(view, 75, 61), 0);  // 2 px below
  EXPECT_NE(depthAt(view, 66, 55), 0);  // 4 px: kept
  EXPECT_NE(depthAt(view, 75, 63), 0);
}

TEST(RangeClean, AStepInDepthIsAnEdgeASlopeIsNot) {
  RangeView view = tiltedPlane(0);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 100; x < kWidth; ++x) {
      view.cameras[0].depth[static_cast<std::size_t>(y) * kWidth + static_cast<std::size_t>(x)] =
          static_cast<std::uint16_t>(1.0 / kUnitM);  // a wall 20 cm behind
    }
  }
  cleanForFusion(view, pinholeRig());
  for (const int x : {98, 99, 100, 101}) {
    EXPECT_EQ(depthAt(view, x, 60), 0) << x;
  }
  EXPECT_NE(depthAt(view, 96, 60), 0);
  EXPECT_NE(depthAt(view, 103, 60), 0);
}

TEST(RangeClean, GrazingIncidenceIsDroppedAtItsAngle) {
  // At the image centre the ray is the optical axis: the incidence is the tilt.
  for (const auto& [tilt, kept] : {std::pair{60.0, true}, {72.0, true}, {78.0, false}}) {
    RangeView view = tiltedPlane(tilt);
    cleanForFusion(view, pinholeRig(), {.edgePx = 0, .jumpPerPx = 1.0, .maxIncidenceDeg = 75});
    EXPECT_EQ(depthAt(view, kWidth / 2, kHeight / 2) != 0, kept) << tilt;
  }
}

TEST(TableCrop, OnlyPointsWithinTheRadiusOfTheAxisStay) {
  RangeView view = tiltedPlane(0);
  // A vertical axis through the plane's centre: a point's distance to it is |x|.
  const TurntableAxis axis{.direction = Eigen::Vector3d(0, -1, 0),
                           .point = Eigen::Vector3d(0, 0, 0.8)};
  keepOnTable(view, pinholeRig(), axis, 0.1);
  const algo::Camera c = pinholeRig().cameras[0];
  for (int x = 0; x < kWidth; ++x) {
    const double worldX = (x - c.cx()) / c.fx() * 0.8;
    if (std::abs(std::abs(worldX) - 0.1) < 0.002) {
      continue;  // on the boundary: rounding decides
    }
    EXPECT_EQ(depthAt(view, x, 60) != 0, std::abs(worldX) < 0.1) << x;
  }
}

}  // namespace
}  // namespace smx::scan
