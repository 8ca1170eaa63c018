#include <gtest/gtest.h>

#include "scan_truth_views.hpp"
#include "smx/algo/lens.hpp"
#include "smx/scan/points.hpp"

namespace smx::scan {
namespace {

// Given the exact depth of a sphere seen through distorted lenses, when it becomes points, then
// every point lies on the sphere (to the depth quantum) and the normals face out, towards the
// camera that saw them.
TEST(ScanPoints, SphereDepthBecomesPointsOnTheSphereWithOutwardNormals) {
  const auto rig = test::twoCameraRig();
  const Eigen::Vector3d centre(0.02, -0.01, 0.85);
  const double radius = 0.08;
  const auto view =
      test::renderView(rig, test::sphereScene(radius, centre), test::tableAxis(), 0.0, "00000");
  ASSERT_EQ(view.cameras.size(), 2U);

  for (std::size_t c = 0; c < 2; ++c) {
    const Cloud cloud = cameraPoints(rig.cameras[c], view.cameras[c], view.depthUnitM);
    ASSERT_GT(cloud.size(), 10000U);
    double worst = 0;
    for (const auto& p : cloud.points) {
      worst = std::max(worst, std::abs((p - centre).norm() - radius));
    }
    // Half a depth unit along a ray that meets the sphere at a slant.
    EXPECT_LT(worst, 0.0005) << "camera " << c;
  }

  const Cloud cloud = viewCloud(rig, view, {.voxelM = 0.002});
  ASSERT_EQ(cloud.normals.size(), cloud.size());
  std::size_t bad = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d truth = (cloud.points[i] - centre).normalized();
    bad += cloud.normals[i].dot(truth) < std::cos(5.0 * std::numbers::pi / 180.0) ? 1U : 0U;
  }
  // The voxel grid keeps one point per 2 mm: about (2π r²)/(2 mm)² of the visible cap.
  EXPECT_GT(cloud.size(), 2000U);
  EXPECT_LT(static_cast<double>(bad), 0.02 * static_cast<double>(cloud.size()));
}

TEST(ScanPoints, TransformMovesPointsAndTurnsNormals) {
  Cloud cloud;
  cloud.points = {{1, 0, 0}};
  cloud.normals = {{0, 1, 0}};
  const Pose pose = Eigen::Translation3d(0, 0, 2) *
                    Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ());
  const Cloud moved = transformed(cloud, pose);
  EXPECT_LT((moved.points[0] - Eigen::Vector3d(0, 1, 2)).norm(), 1e-12);
  EXPECT_LT((moved.normals[0] - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-12);
}

}  // namespace
}  // namespace smx::scan
