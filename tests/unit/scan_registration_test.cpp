#include <gtest/gtest.h>

#include <random>

#include "scan_truth_views.hpp"
#include "smx/scan/points.hpp"
#include "smx/scan/registration.hpp"

namespace smx::scan {
namespace {

double angleDeg(const Eigen::Matrix3d& r) {
  return Eigen::AngleAxisd(r).angle() * 180.0 / std::numbers::pi;
}

class ScanRegistration : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    rig_ = test::twoCameraRig();
    const auto scene = test::bunnyScene();
    a_ = viewCloud(rig_, test::renderView(rig_, scene, test::tableAxis(), 0, "a"),
                   {.voxelM = 0.001});
    b_ = viewCloud(rig_, test::renderView(rig_, scene, test::tableAxis(), 20, "b"),
                   {.voxelM = 0.001});
  }
  // The true motion of the rig frame of view b into that of view a (b's points back by 20°).
  static Pose truthBtoA() { return test::tableMotion(test::tableAxis(), -20); }

  static inline algo::Rig rig_;
  static inline Cloud a_;
  static inline Cloud b_;
};

// Given two views of the bunny 20° apart on the table and a start 1.5° and 4 mm off the truth,
// when ICP registers one onto the other, then it finds the table's motion to 0.1 mm and 0.05°.
TEST_F(ScanRegistration, IcpRecoversTheTableMotionBetweenTwoViews) {
  ASSERT_GT(a_.size(), 5000U);
  ASSERT_GT(b_.size(), 5000U);
  const Pose off =
      Eigen::Translation3d(0.003, -0.002, 0.0015) *
      Eigen::AngleAxisd(1.5 * std::numbers::pi / 180, Eigen::Vector3d(0.3, 1, 0.2).normalized());
  const Pose start = off * truthBtoA();
  const auto r = registerIcp(b_, a_, start);
  ASSERT_TRUE(r.has_value()) << r.error();
  const Pose error = r->pose * truthBtoA().inverse();
  // The error at the object (a rotation error moves points far from the origin).
  const Eigen::Vector3d atObject = error * Eigen::Vector3d(0, 0, 0.9) - Eigen::Vector3d(0, 0, 0.9);
  EXPECT_LT(atObject.norm(), 1e-4);
  EXPECT_LT(angleDeg(error.linear()), 0.05);
  EXPECT_GT(r->fitness, 0.6);
  EXPECT_LT(r->inlierRmseM, 0.001);
  EXPECT_GT(r->information(5, 5), 0.0);  // translation along z is observed
}

// Given the same two views with no initial pose (the first view turned by 40° about its
// centre), when aligned globally, then the alignment is found and is the truth.
TEST_F(ScanRegistration, GlobalAlignmentFindsAViewWithoutAnInitialPose) {
  const Pose turn = test::tableMotion(test::tableAxis(), 40);
  const auto r = alignGlobal(transformed(b_, turn), a_);
  ASSERT_TRUE(r.has_value());
  const Pose error = r->pose * turn * truthBtoA().inverse();
  const Eigen::Vector3d atObject = error * Eigen::Vector3d(0, 0, 0.9) - Eigen::Vector3d(0, 0, 0.9);
  EXPECT_LT(atObject.norm(), 2e-4);
  EXPECT_LT(angleDeg(error.linear()), 0.1);
}

// Given a cloud of random points that is no part of the bunny, when aligned globally, then
// nothing is found (rather than a wrong pose).
TEST_F(ScanRegistration, GlobalAlignmentSaysNotFoundForUnrelatedClouds) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  Cloud noise;
  for (int i = 0; i < 3000; ++i) {
    noise.points.emplace_back(u(random), u(random), 0.9 + u(random));
    noise.normals.push_back(Eigen::Vector3d(u(random), u(random), u(random)).normalized());
  }
  EXPECT_FALSE(alignGlobal(noise, a_).has_value());
}

TEST(ScanRegistrationInput, RefusesEmptyCloudsAndTargetsWithoutNormals) {
  Cloud some;
  some.points = {{0, 0, 1}, {0, 1, 1}, {1, 0, 1}};
  EXPECT_FALSE(registerIcp({}, some, Pose::Identity()).has_value());
  const auto noNormals = registerIcp(some, some, Pose::Identity());
  ASSERT_FALSE(noNormals.has_value());
  EXPECT_NE(noNormals.error().find("normals"), std::string::npos);
}

}  // namespace
}  // namespace smx::scan
