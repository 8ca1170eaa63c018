// Depth scoring on hand-worked planes: every expected number is worked out in the comments.
#include "smx/eval/depth_eval.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace smx::eval {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

struct Case {
  int width = 4;
  int height = 1;
  std::vector<std::uint16_t> depth;
  std::vector<float> truth;
  std::vector<std::uint8_t> region;

  [[nodiscard]] DepthScore score(const DepthScoreOptions& o = {}) const {
    return scoreDepth(*algo::ConstDepthPlane::packed(depth, width, height),
                      *algo::ImageView<const float>::packed(truth, width, height),
                      *algo::ImageView<const std::uint8_t>::packed(region, width, height), o);
  }
};

// Truth 1 m everywhere (gross threshold max(5 mm, 10 mm) = 10 mm); depths in 0.1 mm units:
// 10000 (exact), 10050 (+5 mm, gross under a 5 mm rule), 10099 (+9.9 mm), 10101 (+10.1 mm:
// gross), 0 (missing), and one pixel outside the region with +20 mm.
TEST(DepthEval, CountsCompletenessGrossAndInlierErrors) {
  Case c{6, 1, {10000, 10050, 10099, 10101, 0, 10200}, {1, 1, 1, 1, 1, 1}, {1, 1, 1, 1, 1, 0}};
  const DepthScore s = c.score({.depthUnitM = 1e-4, .fxPx = 800, .baselineM = 0.25});
  EXPECT_EQ(s.regionPixels, 5);
  EXPECT_EQ(s.valid, 4);
  EXPECT_DOUBLE_EQ(s.completeness, 0.8);
  EXPECT_EQ(s.gross, 1);
  EXPECT_DOUBLE_EQ(s.grossRate, 0.25);
  EXPECT_EQ(s.inliers, 3);
  // inlier errors 0, 5, 9.9 mm: RMSE √(123.01/3), mean 14.9/3, max 9.9 (1e-9: float truth 1.0
  // and the unit's 1e-4 are exact enough)
  EXPECT_NEAR(s.rmseMm, std::sqrt(123.01 / 3.0), 1e-9);
  EXPECT_NEAR(s.meanErrorMm, 14.9 / 3.0, 1e-9);
  EXPECT_NEAR(s.maxAbsErrorMm, 9.9, 1e-9);
  // disparity: 800 · 0.25 · e / 1² = 200·e (e in m): 0, 1, 1.98 px → RMS √(4.9204/3)
  EXPECT_NEAR(s.rmsDisparityPx, std::sqrt(4.9204 / 3.0), 1e-9);
  EXPECT_EQ(s.validOutside, 1);
  EXPECT_EQ(s.grossOutside, 1);  // +20 mm
  EXPECT_EQ(s.phantom, 0);
  EXPECT_EQ(s.validTotal, 5);
}

// Near the camera the 5 mm floor applies: at 0.3 m, 1 % is 3 mm; +4 mm is not gross, +5.1 mm is.
// Far away 1 % of the truth (not of the measured depth) applies: at 2 m, +19.9 mm is not gross;
// −20.1 mm is (1 % of the measured 1.9799 m would be 19.8 mm: the same verdict, so also check
// +20.1 mm, where 1 % of the measured 2.0201 m = 20.2 mm would wrongly pass).
TEST(DepthEval, GrossThresholdIsFiveMillimetresOrOnePercentOfTheTruth) {
  EXPECT_FALSE(isGrossError(0.304, 0.3));
  EXPECT_TRUE(isGrossError(0.3051, 0.3));
  EXPECT_FALSE(isGrossError(2.0199, 2.0));
  EXPECT_TRUE(isGrossError(1.9799, 2.0));
  EXPECT_TRUE(isGrossError(2.0201, 2.0));
}

// NaN truth: not in the region whatever the mask says; a depth there is a phantom point.
TEST(DepthEval, NoSurfaceIsOutsideTheRegionAndDepthThereIsPhantom) {
  Case c{4, 1, {9000, 0, 9000, 0}, {kNaN, kNaN, 0.9F, 0.9F}, {1, 1, 1, 1}};
  const DepthScore s = c.score();
  EXPECT_EQ(s.regionPixels, 2);
  EXPECT_EQ(s.valid, 1);
  EXPECT_EQ(s.phantom, 1);
  EXPECT_EQ(s.validOutside, 0);
  const auto map = depthErrorMapMm(*algo::ConstDepthPlane::packed(c.depth, 4, 1),
                                   *algo::ImageView<const float>::packed(c.truth, 4, 1));
  EXPECT_TRUE(std::isnan(map[0]));
  EXPECT_NEAR(map[2], 0.0, 1e-3);  // 0.9F is 0.89999998 m
  EXPECT_TRUE(std::isnan(map[3]));
}

TEST(DepthEval, EmptyRegionGivesZerosAndSizeMismatchThrows) {
  Case c{2, 1, {100, 0}, {1, 1}, {0, 0}};
  const DepthScore s = c.score();
  EXPECT_EQ(s.regionPixels, 0);
  EXPECT_EQ(s.completeness, 0);
  EXPECT_EQ(s.rmseMm, 0);
  EXPECT_EQ(s.validOutside, 1);
  std::vector<float> truth(3, 1.0F);
  EXPECT_THROW((void)scoreDepth(*algo::ConstDepthPlane::packed(c.depth, 2, 1),
                                *algo::ImageView<const float>::packed(truth, 3, 1),
                                *algo::ImageView<const std::uint8_t>::packed(c.region, 2, 1)),
               std::invalid_argument);
}

}  // namespace
}  // namespace smx::eval
