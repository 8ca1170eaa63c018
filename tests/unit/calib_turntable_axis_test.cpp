// The turntable axis fit against views generated from a known axis: the target's pose at each
// table angle is its first pose turned about the true line, plus the noise a solvePnP pose has.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>
#include <random>
#include <vector>

#include "smx/calib/turntable_axis.hpp"

namespace smx::calib {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
const Target kTarget{.cols = 11, .rows = 8, .squareM = 0.03};

struct TrueTable {
  Eigen::Vector3d direction = Eigen::Vector3d(0.05, -1.0, 0.12).normalized();
  Eigen::Vector3d through = Eigen::Vector3d(0.03, 0.2, 0.85);  // any point on the axis
  double angleScale = 1.0;
};

// The target leaning back on the table, facing the camera, turned by each angle.
std::vector<TableView> viewsOf(const TrueTable& table, const std::vector<double>& anglesDeg,
                               double rotationNoiseDeg, double translationNoiseM,
                               std::uint32_t seed) {
  const Eigen::Matrix3d baseR(Eigen::AngleAxisd(-50.0 * kRadPerDeg, Eigen::Vector3d::UnitX()));
  const Eigen::Vector3d baseT(-0.15, 0.12, 0.8);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<TableView> views;
  for (std::size_t i = 0; i < anglesDeg.size(); ++i) {
    const double turn = anglesDeg[i] * table.angleScale * kRadPerDeg;
    const Eigen::Matrix3d q(Eigen::AngleAxisd(turn, table.direction));
    TableView view;
    view.name = "view" + std::to_string(i);
    view.angleDeg = anglesDeg[i];
    const Eigen::Vector3d wobble(noise(rng), noise(rng), noise(rng));
    view.R = Eigen::AngleAxisd(rotationNoiseDeg * kRadPerDeg * wobble.norm(), wobble.normalized()) *
             q * baseR;
    view.t = q * (baseT - table.through) + table.through +
             translationNoiseM * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    views.push_back(view);
  }
  return views;
}

double distanceToLine(const Eigen::Vector3d& x, const Eigen::Vector3d& point,
                      const Eigen::Vector3d& direction) {
  return (x - point).cross(direction).norm();
}

const std::vector<double> kAngles = {-40, -25, -10, 5, 20, 35};

TEST(TurntableAxis, RecoversTheTrueLineFromNoisyTargetPoses) {
  const TrueTable table;
  const auto fit = fitTurntableAxis(viewsOf(table, kAngles, 0.02, 0.0002, 7), kTarget);
  ASSERT_TRUE(fit) << fit.error();
  EXPECT_LT(std::acos(std::min(1.0, fit->direction.dot(table.direction))) / kRadPerDeg, 0.1);
  // The fitted point lies on the true line, and the true point on the fitted line.
  EXPECT_LT(distanceToLine(fit->point, table.through, table.direction), 0.001);
  EXPECT_LT(distanceToLine(table.through, fit->point, fit->direction), 0.001);
  EXPECT_NEAR(fit->point.dot(fit->direction), 0.0, 1e-9);  // nearest the origin
  EXPECT_NEAR(fit->angleScale, 1.0, 0.005);
  EXPECT_LT(fit->cornerRmsM, 0.001);
  EXPECT_EQ(fit->viewRmsM.size(), kAngles.size());
}

TEST(TurntableAxis, ExactPosesGiveTheExactAxis) {
  const TrueTable table;
  const auto fit = fitTurntableAxis(viewsOf(table, kAngles, 0.0, 0.0, 1), kTarget);
  ASSERT_TRUE(fit) << fit.error();
  EXPECT_NEAR(fit->direction.dot(table.direction), 1.0, 1e-12);
  EXPECT_LT(distanceToLine(fit->point, table.through, table.direction), 1e-9);
  EXPECT_LT(fit->cornerRmsM, 1e-9);
}

TEST(TurntableAxis, ATableThatTurnsLessThanItsStepsSayShowsInTheScale) {
  TrueTable table;
  table.angleScale = 0.98;
  const auto fit = fitTurntableAxis(viewsOf(table, kAngles, 0.0, 0.0, 1), kTarget);
  ASSERT_TRUE(fit) << fit.error();
  EXPECT_NEAR(fit->angleScale, 0.98, 1e-9);
  EXPECT_LT(distanceToLine(fit->point, table.through, table.direction), 1e-9);
}

TEST(TurntableAxis, RefusesTooFewViewsTooSmallASpanAndASlidTarget) {
  const TrueTable table;
  const auto few = fitTurntableAxis(viewsOf(table, {0, 20, 40}, 0, 0, 1), kTarget);
  ASSERT_FALSE(few);
  EXPECT_NE(few.error().find("at 3 table angles, at least 4"), std::string::npos) << few.error();

  const auto narrow = fitTurntableAxis(viewsOf(table, {0, 5, 10, 15, 20}, 0, 0, 1), kTarget);
  ASSERT_FALSE(narrow);
  EXPECT_NE(narrow.error().find("span 20.0°"), std::string::npos) << narrow.error();

  auto slid = viewsOf(table, kAngles, 0, 0, 1);
  slid[3].R = Eigen::AngleAxisd(3.0 * kRadPerDeg, Eigen::Vector3d::UnitZ()) * slid[3].R;
  const auto moved = fitTurntableAxis(slid, kTarget);
  ASSERT_FALSE(moved);
  EXPECT_NE(moved.error().find("view3"), std::string::npos) << moved.error();
  EXPECT_NE(moved.error().find("slid"), std::string::npos) << moved.error();
}

}  // namespace
}  // namespace smx::calib
