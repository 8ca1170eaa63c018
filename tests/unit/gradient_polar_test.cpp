// The division-free doubled angle and magnitude of histogramTiles() (gradient_polar.hpp) against
// std::atan2 and std::hypot over its whole domain, |gx|, |gy| < 2^14.
#include "gradient_polar.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <random>

namespace smx::algo::demux {
namespace {

constexpr double kAngleBound = 0.55;   // raw units (2^16 per turn) of the doubled angle
constexpr double kWeightBound = 0.54;  // absolute, |g| < 2^14 · √2

struct Worst {
  double angle = 0.0;
  double weight = 0.0;
  double weightRelative = 0.0;
};

void check(std::int32_t gx, std::int32_t gy, Worst& worst) {
  const GradientPolar got = gradientPolar(gx, gy);
  const double x = gx;
  const double y = gy;
  const double turns2 = std::atan2(y, x) / std::numbers::pi;  // doubled angle in turns
  double diff = static_cast<double>(got.angle2) - turns2 * 65536.0;
  diff = std::remainder(diff, 65536.0);
  const double norm = std::hypot(x, y);
  const double weightError = std::abs(static_cast<double>(got.weight) - norm);
  worst.angle = std::max(worst.angle, std::abs(diff));
  worst.weight = std::max(worst.weight, weightError);
  worst.weightRelative = std::max(worst.weightRelative, weightError / norm);
  ASSERT_LE(std::abs(diff), kAngleBound) << gx << ", " << gy;
  ASSERT_LE(weightError, kWeightBound) << gx << ", " << gy;
}

void report(const char* what, const Worst& worst) {
  std::printf("GradientPolar worst-case (%s): angle %.4f raw, weight %.4f (%.2e relative)\n", what,
              worst.angle, worst.weight, worst.weightRelative);
}

TEST(GradientPolar, ExactOnAxesAndDiagonalsAndZeroAtTheOrigin) {
  EXPECT_EQ(gradientPolar(0, 0).angle2, 0);
  EXPECT_EQ(gradientPolar(0, 0).weight, 0);
  for (const std::int32_t m : {1, 2, 3, 100, 8191, 8192, 16383}) {
    EXPECT_EQ(gradientPolar(m, 0).angle2, 0) << m;       // 0
    EXPECT_EQ(gradientPolar(0, m).angle2, 32768) << m;   // π/2 doubled
    EXPECT_EQ(gradientPolar(-m, 0).angle2, 0) << m;      // π doubled
    EXPECT_EQ(gradientPolar(0, -m).angle2, 32768) << m;  // −π/2 doubled
    EXPECT_EQ(gradientPolar(m, m).angle2, 16384) << m;   // π/4 doubled
    EXPECT_EQ(gradientPolar(-m, m).angle2, 49152) << m;
    EXPECT_EQ(gradientPolar(-m, -m).angle2, 16384) << m;
    EXPECT_EQ(gradientPolar(m, -m).angle2, 49152) << m;
    EXPECT_EQ(gradientPolar(m, 0).weight, m);
    EXPECT_EQ(gradientPolar(0, -m).weight, m);
  }
}

TEST(GradientPolar, WithinBoundOnAnExhaustiveSquare) {
  Worst worst;
  for (std::int32_t gy = -600; gy <= 600; ++gy) {
    for (std::int32_t gx = -600; gx <= 600; ++gx) {
      if (gx != 0 || gy != 0) {
        ASSERT_NO_FATAL_FAILURE(check(gx, gy, worst));
      }
    }
  }
  report("|g| <= 600", worst);
}

// Every larger side hi < 2^14 (every normalisation and reciprocal interval), each with a sweep
// of the smaller side, in all eight octants.
TEST(GradientPolar, WithinBoundForEveryMagnitudeInEveryOctant) {
  Worst worst;
  for (std::int32_t hi = 1; hi < (1 << 14); ++hi) {
    const std::int32_t step = hi / 37 + 1;
    for (std::int32_t lo = 0; lo <= hi; lo += (lo + step > hi && lo != hi) ? hi - lo : step) {
      for (const std::int32_t sx : {1, -1}) {
        for (const std::int32_t sy : {1, -1}) {
          ASSERT_NO_FATAL_FAILURE(check(sx * hi, sy * lo, worst));
          ASSERT_NO_FATAL_FAILURE(check(sx * lo, sy * hi, worst));
        }
      }
      if (lo == hi) {
        break;
      }
    }
  }
  report("every hi", worst);
}

TEST(GradientPolar, WithinBoundOnRandomGradients) {
  std::mt19937 rng(20240611);
  std::uniform_int_distribution<std::int32_t> component(-(1 << 14) + 1, (1 << 14) - 1);
  Worst worst;
  for (int n = 0; n < 4'000'000; ++n) {
    const std::int32_t gx = component(rng);
    const std::int32_t gy = component(rng);
    if (gx != 0 || gy != 0) {
      ASSERT_NO_FATAL_FAILURE(check(gx, gy, worst));
    }
  }
  report("random", worst);
}

}  // namespace
}  // namespace smx::algo::demux
