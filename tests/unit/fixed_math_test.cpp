#include "smx/algo/fixed_math.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <utility>

namespace smx::algo {
namespace {

// Every kernel is measured against double (<cmath>) over its whole domain, exhaustively where the
// domain is small and by boundaries plus seeded random samples where it is not. The documented
// bounds (fixed_math.hpp, docs/fixed-point.md) are asserted; the measured worst cases are printed
// as "FixedMath worst-case: ..." lines and recorded as test properties.

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kSinBoundLsb = 0.58;            // 0.5 rounding + 0.077 interpolation
constexpr double kAtan2BoundLsb = 0.52;          // 0.5 rounding + 0.013 interpolation
constexpr double kRecipBoundUnits = 0.5 + 1e-5;  // correctly rounded; slack for the double ref
constexpr double kSqrtBound = 0.5 + 1e-5;        // nearest; slack for the double ref

std::uint32_t next32(std::mt19937& rng) {
  return static_cast<std::uint32_t>(rng());
}

void report(const char* what, double worst, double bound, const char* unit) {
  ::testing::Test::RecordProperty(std::string(what) + "WorstCase", std::to_string(worst));
  ::testing::Test::RecordProperty(std::string(what) + "Bound", std::to_string(bound));
  std::printf("FixedMath worst-case: %s %.7f %s (bound %.5f)\n", what, worst, unit, bound);
}

// ---- BinAngle -------------------------------------------------------------------------------

TEST(FixedMathAngle, DoublingWrapsAndHalvingGivesTheOrientation) {
  for (std::uint32_t a = 0; a < BinAngle::kFullTurn; ++a) {
    const BinAngle angle{static_cast<std::uint16_t>(a)};
    // Doubling is 2θ mod 2π
    ASSERT_EQ(angle.doubled().raw, (2 * a) % 65536);
    // Halving the double gives θ mod π
    ASSERT_EQ(angle.doubled().halved().raw, a % 32768);
    // Halving drops at most 1 LSB: 2·halved is θ or θ - 1 LSB
    ASSERT_EQ(angle.halved().doubled().raw, a & ~1U);
  }
}

TEST(FixedMathAngle, ArithmeticWrapsAndConversionsRoundToNearest) {
  EXPECT_EQ((BinAngle{65000} + BinAngle{1000}).raw, 464);
  EXPECT_EQ((BinAngle{10} - BinAngle{20}).raw, 65526);
  EXPECT_EQ((-BinAngle{16384}).raw, 49152);
  EXPECT_EQ(BinAngle::fromDegrees(90.0).raw, 16384);
  EXPECT_EQ(BinAngle::fromDegrees(-90.0).raw, 49152);
  EXPECT_EQ(BinAngle::fromDegrees(360.0).raw, 0);
  EXPECT_EQ(BinAngle::fromDegrees(765.0).raw, 8192);  // 2 turns + 45°
  EXPECT_EQ(BinAngle::fromDegrees(-0.001).raw, 0);    // rounds to 0, not 65535
  EXPECT_EQ(BinAngle::fromRadians(std::numbers::pi).raw, 32768);
  EXPECT_EQ(BinAngle::fromRadians(-std::numbers::pi / 2).raw, 49152);
  EXPECT_EQ(BinAngle::fromDegrees(std::numeric_limits<double>::quiet_NaN()).raw, 0);
  EXPECT_DOUBLE_EQ(BinAngle{8192}.toDegrees(), 45.0);
  EXPECT_DOUBLE_EQ(BinAngle{32768}.toRadians(), std::numbers::pi);
  // One LSB is 360/65536 degrees; conversions round to the nearest
  EXPECT_EQ(BinAngle::fromDegrees(360.0 / 65536 * 0.49).raw, 0);
  EXPECT_EQ(BinAngle::fromDegrees(360.0 / 65536 * 0.51).raw, 1);
  for (std::uint32_t a = 0; a < BinAngle::kFullTurn; a += 97) {
    const BinAngle angle{static_cast<std::uint16_t>(a)};
    ASSERT_EQ(BinAngle::fromDegrees(angle.toDegrees()), angle);
    ASSERT_EQ(BinAngle::fromRadians(angle.toRadians()), angle);
  }
}

// ---- sin / cos ------------------------------------------------------------------------------

TEST(FixedMath, SinAndCosOfEveryBinAngleAreWithinBoundOfLibm) {
  // Given every binary angle
  double worstSin = 0.0;
  double worstCos = 0.0;
  for (std::uint32_t a = 0; a < BinAngle::kFullTurn; ++a) {
    const BinAngle angle{static_cast<std::uint16_t>(a)};
    // When sin and cos are evaluated
    const std::int16_t s = sin(angle);
    const std::int16_t c = cos(angle);
    // Then they are within the bound of libm, in LSB of Q1.14
    const double radians = static_cast<double>(a) / 65536.0 * kTwoPi;
    worstSin = std::max(worstSin, std::abs(s - std::sin(radians) * 16384.0));
    worstCos = std::max(worstCos, std::abs(c - std::cos(radians) * 16384.0));
    // And the symmetries hold bit for bit
    ASSERT_EQ(sin(-angle), -s) << a;
    ASSERT_EQ(c, sin(angle + BinAngle{16384})) << a;
  }
  report("sin", worstSin, kSinBoundLsb, "LSB(Q1.14)");
  report("cos", worstCos, kSinBoundLsb, "LSB(Q1.14)");
  EXPECT_LE(worstSin, kSinBoundLsb);
  EXPECT_LE(worstCos, kSinBoundLsb);
}

TEST(FixedMath, SinIsExactAtTheQuadrantPoints) {
  EXPECT_EQ(sin(BinAngle{0}), 0);
  EXPECT_EQ(sin(BinAngle{16384}), 16384);
  EXPECT_EQ(sin(BinAngle{32768}), 0);
  EXPECT_EQ(sin(BinAngle{49152}), -16384);
  EXPECT_EQ(cos(BinAngle{0}), 16384);
  EXPECT_EQ(cos(BinAngle{32768}), -16384);
  EXPECT_EQ(sin(BinAngle{8192}), 11585);  // round(16384 / √2) = round(11585.24)
}

// ---- atan2 ----------------------------------------------------------------------------------

// Error of a result in LSB (2π / 65536) against std::atan2, wrapped into [-32768, 32768].
double atanErrorLsb(BinAngle got, double y, double x) {
  const double ref = std::atan2(y, x) / kTwoPi * 65536.0;
  return std::abs(std::remainder(static_cast<double>(got.raw) - ref, 65536.0));
}

TEST(FixedMath, Atan2IsWithinBoundOverAnExhaustiveSquare) {
  // Given every integer vector in [-1024, 1024]² except the origin
  constexpr int kHalfSide = 1024;
  double worst = 0.0;
  for (int y = -kHalfSide; y <= kHalfSide; ++y) {
    for (int x = -kHalfSide; x <= kHalfSide; ++x) {
      if (x == 0 && y == 0) {
        continue;
      }
      // When atan2 is evaluated; Then it is within the bound of libm
      const double e = atanErrorLsb(atan2(y, x), y, x);
      worst = std::max(worst, e);
    }
  }
  report("atan2 (square)", worst, kAtan2BoundLsb, "LSB(2pi/65536)");
  EXPECT_LE(worst, kAtan2BoundLsb);
}

TEST(FixedMath, Atan2IsWithinBoundOnRandomInt32AndInt64) {
  std::mt19937_64 rng(314159);
  double worst32 = 0.0;
  double worst64 = 0.0;
  for (int i = 0; i < 100000; ++i) {
    // Given seeded random int32 vectors over the full range
    const auto y32 = static_cast<std::int32_t>(rng());
    const auto x32 = static_cast<std::int32_t>(rng());
    worst32 = std::max(worst32, atanErrorLsb(atan2(y32, x32), y32, x32));
    // And int64 vectors of random magnitude (shifted so every scale up to 2^63 is visited)
    const int shiftY = static_cast<int>(rng() % 64);
    const int shiftX = static_cast<int>(rng() % 64);
    const auto y64 = static_cast<std::int64_t>(rng()) >> shiftY;
    const auto x64 = static_cast<std::int64_t>(rng()) >> shiftX;
    if (x64 == 0 && y64 == 0) {
      continue;
    }
    const BinAngle a64 = atan2(y64, x64);
    worst64 =
        std::max(worst64, atanErrorLsb(a64, static_cast<double>(y64), static_cast<double>(x64)));
    // Then the sign-flip symmetries hold bit for bit
    if (y64 != std::numeric_limits<std::int64_t>::min()) {
      ASSERT_EQ(atan2(-y64, x64), -a64) << y64 << ", " << x64;
    }
  }
  report("atan2 (random int32)", worst32, kAtan2BoundLsb, "LSB(2pi/65536)");
  report("atan2 (random int64)", worst64, kAtan2BoundLsb, "LSB(2pi/65536)");
  EXPECT_LE(worst32, kAtan2BoundLsb);
  EXPECT_LE(worst64, kAtan2BoundLsb);
}

TEST(FixedMath, Atan2IsExactOnAxesAndDiagonalsAndDefinedAtTheOrigin) {
  constexpr std::int32_t kMin32 = std::numeric_limits<std::int32_t>::min();
  constexpr std::int32_t kMax32 = std::numeric_limits<std::int32_t>::max();
  constexpr std::int64_t kMin64 = std::numeric_limits<std::int64_t>::min();
  constexpr std::int64_t kMax64 = std::numeric_limits<std::int64_t>::max();
  // The origin is defined as 0
  EXPECT_EQ(atan2(0, 0).raw, 0);
  EXPECT_EQ(atan2(std::int64_t{0}, std::int64_t{0}).raw, 0);
  // Axes and diagonals at every scale, including the most negative values
  for (const std::int64_t k :
       {std::int64_t{1}, std::int64_t{3}, std::int64_t{1} << 31, std::int64_t{kMax32}, kMax64}) {
    EXPECT_EQ(atan2(std::int64_t{0}, k).raw, 0);
    EXPECT_EQ(atan2(k, std::int64_t{0}).raw, 16384);
    EXPECT_EQ(atan2(std::int64_t{0}, -k).raw, 32768);
    EXPECT_EQ(atan2(-k, std::int64_t{0}).raw, 49152);
    EXPECT_EQ(atan2(k, k).raw, 8192);
    EXPECT_EQ(atan2(k, -k).raw, 24576);
    EXPECT_EQ(atan2(-k, -k).raw, 40960);
    EXPECT_EQ(atan2(-k, k).raw, 57344);
  }
  EXPECT_EQ(atan2(kMin32, 0).raw, 49152);
  EXPECT_EQ(atan2(0, kMin32).raw, 32768);
  EXPECT_EQ(atan2(kMin32, kMin32).raw, 40960);
  EXPECT_EQ(atan2(kMin64, kMin64).raw, 40960);
  EXPECT_EQ(atan2(kMin64, std::int64_t{0}).raw, 49152);
  // Near-axis and extreme-ratio edges against libm
  double worst = 0.0;
  const std::array<std::pair<std::int64_t, std::int64_t>, 10> edges = {{
      {kMin32, kMax32},
      {kMax32, kMin32},
      {1, kMax32},
      {kMin32, 1},
      {-1, kMin32},
      {1, kMin64},
      {kMin64, kMax64},
      {kMax64, -1},
      {kMax64, kMax64 - 1},
      {kMin64 + 1, kMin64},
  }};
  for (const auto& [y, x] : edges) {
    worst =
        std::max(worst, atanErrorLsb(atan2(y, x), static_cast<double>(y), static_cast<double>(x)));
  }
  report("atan2 (edges)", worst, kAtan2BoundLsb, "LSB(2pi/65536)");
  EXPECT_LE(worst, kAtan2BoundLsb);
  // The int32 overload agrees with the int64 one
  EXPECT_EQ(atan2(kMin32, kMax32), atan2(std::int64_t{kMin32}, std::int64_t{kMax32}));
}

// ---- reciprocal / divide --------------------------------------------------------------------

// Error of a reciprocal in units of its mantissa, against double; also checks normalisation and
// the exact correct-rounding predicate |2^shift - mantissa·x| <= x / 2.
double recipErrorUnits(std::uint32_t x) {
  const Reciprocal r = reciprocal(x);
  EXPECT_GE(r.mantissa, 1U << 31) << x;
  EXPECT_TRUE(r.shift >= 31 && r.shift <= 63) << x;
  const std::uint64_t target = std::uint64_t{1} << r.shift;
  const auto residual = static_cast<std::int64_t>(target - std::uint64_t{r.mantissa} * x);
  EXPECT_LE(2 * std::abs(residual), std::int64_t{x}) << x;
  return std::abs(static_cast<double>(r.mantissa) - std::ldexp(1.0, r.shift) / x);
}

TEST(FixedMath, ReciprocalIsCorrectlyRounded) {
  // Given every x up to 2^20 (every seed-table entry, every 20-bit mantissa), all powers of two
  // and their neighbours, and seeded random uint32
  double worst = 0.0;
  for (std::uint32_t x = 1; x <= (1U << 20); ++x) {
    worst = std::max(worst, recipErrorUnits(x));
  }
  for (int b = 0; b < 32; ++b) {
    const std::uint32_t p = 1U << b;
    worst = std::max(
        {worst, recipErrorUnits(p), recipErrorUnits(p + 1), recipErrorUnits(p == 1 ? 1 : p - 1)});
    // Powers of two are exact
    EXPECT_EQ(reciprocal(p).mantissa, 1U << 31);
    EXPECT_EQ(reciprocal(p).shift, 31 + b);
  }
  worst = std::max(worst, recipErrorUnits(0xFFFFFFFFU));
  std::mt19937 rng(2718);
  for (int i = 0; i < 200000; ++i) {
    const std::uint32_t x = next32(rng) | 1U;  // never zero
    worst = std::max(worst, recipErrorUnits(x));
  }
  // Then the mantissa is within half a unit of 2^shift / x (relative error <= 2^-32)
  report("reciprocal", worst, kRecipBoundUnits, "units of mantissa");
  EXPECT_LE(worst, kRecipBoundUnits);
  // And zero saturates
  EXPECT_EQ(reciprocal(0).mantissa, 0xFFFFFFFFU);
  EXPECT_EQ(reciprocal(0).shift, 0);
}

TEST(FixedMath, MulReciprocalIsWithinItsBound) {
  // Given seeded random numerators and denominators of every magnitude
  std::mt19937 rng(1618);
  double worstNearest = 0.0;
  double worstTruncating = 0.0;
  for (int i = 0; i < 100000; ++i) {
    const std::uint32_t a = next32(rng);
    const std::uint32_t x = std::max(1U, next32(rng) >> (next32(rng) % 32));
    const Reciprocal r = reciprocal(x);
    const double exact = static_cast<double>(a) / x;
    // When a / x is formed by multiply and shift
    // Then nearest modes are within 0.5 + 0.25, truncating ones within 1 + 0.25 (below) of a / x
    for (Round mode : {Round::kHalfUp, Round::kHalfEven}) {
      worstNearest = std::max(worstNearest, std::abs(mulReciprocal(a, r, mode) - exact));
    }
    for (Round mode : {Round::kFloor, Round::kTowardZero}) {
      const double e = mulReciprocal(a, r, mode) - exact;
      ASSERT_LE(e, 0.25) << a << " / " << x;
      worstTruncating = std::max(worstTruncating, std::abs(e));
    }
  }
  report("mulReciprocal (nearest)", worstNearest, 0.75, "LSB");
  report("mulReciprocal (floor)", worstTruncating, 1.25, "LSB");
  EXPECT_LT(worstNearest, 0.75);
  EXPECT_LT(worstTruncating, 1.25);
  // Powers of two are exact; zero saturates
  EXPECT_EQ(mulReciprocal(0xFFFFFFFFU, reciprocal(1), Round::kFloor), 0xFFFFFFFFU);
  EXPECT_EQ(mulReciprocal(12345, reciprocal(0), Round::kFloor), 0xFFFFFFFFU);
}

// Exactly rounded quotient by integer division, an independent method.
std::uint32_t divideRef(std::uint32_t num, std::uint32_t den, Round round) {
  const std::uint64_t q = num / den;
  const std::uint64_t r = num % den;
  bool up = false;
  switch (round) {
    case Round::kFloor:
    case Round::kTowardZero:
      break;
    case Round::kHalfUp:
      up = 2 * r >= den;
      break;
    case Round::kHalfEven:
      up = 2 * r > den || (2 * r == den && q % 2 == 1);
      break;
  }
  return static_cast<std::uint32_t>(up ? q + 1 : q);
}

TEST(FixedMath, DivideIsExactlyRounded) {
  constexpr std::array<Round, 4> kModes = {Round::kFloor, Round::kHalfUp, Round::kHalfEven,
                                           Round::kTowardZero};
  int cases = 0;
  auto check = [&](std::uint32_t num, std::uint32_t den) {
    for (Round mode : kModes) {
      ASSERT_EQ(divide(num, den, mode), divideRef(num, den, mode)) << num << " / " << den;
    }
    ++cases;
  };
  // Given every pair of small numbers (all ties and remainders of small denominators)
  for (std::uint32_t num = 0; num < 300; ++num) {
    for (std::uint32_t den = 1; den < 300; ++den) {
      check(num, den);
    }
  }
  // And the extremes
  constexpr std::uint32_t kMax = 0xFFFFFFFFU;
  for (std::uint32_t den : {1U, 2U, 3U, 0x7FFFFFFFU, 0x80000000U, 0x80000001U, kMax - 1, kMax}) {
    for (std::uint32_t num : {0U, 1U, den - 1, den, den + 1, kMax / 2, kMax - 1, kMax}) {
      check(num, den);
    }
  }
  // And seeded random pairs of every magnitude
  std::mt19937 rng(4242);
  for (int i = 0; i < 100000; ++i) {
    const std::uint32_t num = next32(rng) >> (next32(rng) % 32);
    const std::uint32_t den = std::max(1U, next32(rng) >> (next32(rng) % 32));
    check(num, den);
  }
  // Then all agree exactly; zero denominators saturate
  EXPECT_EQ(divide(7, 0, Round::kHalfUp), kMax);
  EXPECT_EQ(divide(0, 0, Round::kFloor), kMax);
  std::printf("FixedMath worst-case: divide 0 LSB (exact on %d cases x 4 modes)\n", cases);
}

// ---- isqrt ----------------------------------------------------------------------------------

// Exact check that r is the nearest integer to √x: r² - r < x <= r² + r (no overflow: r <= 2^32).
bool isNearestRoot(std::uint64_t x, std::uint64_t r) {
  if (r == 0) {
    return x == 0;
  }
  const bool above = x > r * (r - 1);
  const bool below = r >= (std::uint64_t{1} << 32) || x <= r * (r + 1);
  return above && below;
}

TEST(FixedMath, Isqrt32IsNearestAtEveryStep) {
  // Given, for every root r, the inputs where floor and nearest roots change:
  // r² - 1, r², r² + r and r² + r + 1 (the last two straddle √x = r + 1/2)
  double worst = 0.0;
  auto check = [&](std::uint64_t x64) {
    const auto x = static_cast<std::uint32_t>(x64);
    const std::uint32_t r = isqrt(x);
    ASSERT_TRUE(isNearestRoot(x, r)) << x << " -> " << r;
    worst = std::max(worst, std::abs(r - std::sqrt(static_cast<double>(x))));
  };
  for (std::uint64_t r = 0; r <= 65535; ++r) {
    for (std::uint64_t x : {r * r, r * r + r, r * r + r + 1}) {
      check(x);
    }
    if (r > 0) {
      check(r * r - 1);
    }
  }
  check(0xFFFFFFFFU);  // rounds up to 65536
  EXPECT_EQ(isqrt(0xFFFFFFFFU), 65536U);
  std::mt19937 rng(1414);
  for (int i = 0; i < 100000; ++i) {
    check(next32(rng) >> (next32(rng) % 32));
  }
  // Then every result is the nearest root
  report("isqrt32", worst, kSqrtBound, "LSB");
  EXPECT_LE(worst, kSqrtBound);
}

TEST(FixedMath, Isqrt64IsNearestAtSampledSteps) {
  double worst = 0.0;
  auto check = [&](std::uint64_t x) {
    const std::uint64_t r = isqrt(x);
    ASSERT_TRUE(isNearestRoot(x, r)) << x << " -> " << r;
    worst = std::max(worst, std::abs(static_cast<double>(r) - std::sqrt(static_cast<double>(x))));
  };
  auto steps = [&](std::uint64_t r) {
    check(r * r);
    check(r * r + r);
    check(r * r + r + 1);
    if (r > 0) {
      check(r * r - 1);
    }
  };
  // Given every step for roots below 2^16, steps at seeded random roots of every magnitude
  // up to 2^32 - 1, the top of the range and random inputs
  for (std::uint64_t r = 0; r < (1U << 16); ++r) {
    steps(r);
  }
  std::mt19937_64 rng(1732);
  for (int i = 0; i < 50000; ++i) {
    steps((rng() >> 32) >> (rng() % 32));
    check(rng() >> (rng() % 64));
  }
  constexpr std::uint64_t kTop = 0xFFFFFFFFU;
  steps(kTop);
  check(std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(isqrt(std::numeric_limits<std::uint64_t>::max()), std::uint64_t{1} << 32);
  EXPECT_EQ(isqrt(kTop * kTop + kTop), kTop);
  EXPECT_EQ(isqrt(kTop * kTop + kTop + 1), kTop + 1);
  // Then every result is the nearest root (the double comparison is only good to ~1e-6 here;
  // the exact predicate above is what decides)
  report("isqrt64", worst, kSqrtBound, "LSB");
  EXPECT_LE(worst, kSqrtBound);
}

// Full sweeps of the 32-bit domains: minutes under emulation, so run by hand
// (--gtest_also_run_disabled_tests --gtest_filter='FixedMath.DISABLED_*').
TEST(FixedMath, DISABLED_ReciprocalOfEveryUint32IsCorrectlyRounded) {
  for (std::uint64_t x = 1; x <= 0xFFFFFFFFU; ++x) {
    const auto x32 = static_cast<std::uint32_t>(x);
    const Reciprocal r = reciprocal(x32);
    const auto residual =
        static_cast<std::int64_t>((std::uint64_t{1} << r.shift) - std::uint64_t{r.mantissa} * x);
    ASSERT_LE(2 * std::abs(residual), static_cast<std::int64_t>(x)) << x;
    ASSERT_GE(r.mantissa, 1U << 31) << x;
  }
}

TEST(FixedMath, DISABLED_IsqrtOfEveryUint32IsNearest) {
  for (std::uint64_t x = 0; x <= 0xFFFFFFFFU; ++x) {
    ASSERT_TRUE(isNearestRoot(x, isqrt(static_cast<std::uint32_t>(x)))) << x;
  }
}

}  // namespace
}  // namespace smx::algo
