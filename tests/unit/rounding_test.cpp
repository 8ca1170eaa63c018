#include "smx/algo/rounding.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

namespace smx::algo {
namespace {

// References are computed independently, in double with <cmath> or in exact integer arithmetic
// by a different method than the code under test, so a wrong implementation fails here.

constexpr std::array<Round, 4> kAllRounds = {Round::kFloor, Round::kHalfUp, Round::kHalfEven,
                                             Round::kTowardZero};

const char* name(Round r) {
  switch (r) {
    case Round::kFloor:
      return "Floor";
    case Round::kHalfUp:
      return "HalfUp";
    case Round::kHalfEven:
      return "HalfEven";
    case Round::kTowardZero:
      return "TowardZero";
  }
  return "?";
}

// Rounds a double that is exactly representable with its neighbours (|v| < 2^51).
double roundRef(double v, Round r) {
  switch (r) {
    case Round::kFloor:
      return std::floor(v);
    case Round::kHalfUp:
      return std::floor(v + 0.5);  // exact below 2^51
    case Round::kHalfEven:
      return std::nearbyint(v);  // default FE_TONEAREST: ties to even
    case Round::kTowardZero:
      return std::trunc(v);
  }
  return NAN;
}

static_assert(roundingShiftRight(-3, 1, Round::kHalfEven) == -2);
static_assert(saturateCast<std::int8_t>(300) == 127);

TEST(Rounding, RoundDoubleRoundsHalvesAsEachModeSays) {
  // Given values exactly halfway (and not halfway) between two integers
  // When converted with each rounding mode
  // Then the raw value is the hand-derived one (columns: Floor, HalfUp, HalfEven, TowardZero)
  struct Case {
    double lsb;
    std::array<int, 4> expected;
  };
  const std::array<Case, 12> cases = {{
      {2.5, {2, 3, 2, 2}},
      {-2.5, {-3, -2, -2, -2}},
      {1.5, {1, 2, 2, 1}},
      {-1.5, {-2, -1, -2, -1}},
      {0.5, {0, 1, 0, 0}},
      {-0.5, {-1, 0, 0, 0}},
      {2.3, {2, 2, 2, 2}},
      {-2.3, {-3, -2, -2, -2}},
      {2.7, {2, 3, 3, 2}},
      {-2.7, {-3, -3, -3, -2}},
      {3.0, {3, 3, 3, 3}},
      {-3.0, {-3, -3, -3, -3}},
  }};
  for (const Case& c : cases) {
    for (std::size_t m = 0; m < kAllRounds.size(); ++m) {
      EXPECT_EQ(detail::roundDouble(c.lsb, kAllRounds[m], -128, 127), c.expected[m])
          << c.lsb << " LSB, " << name(kAllRounds[m]);
    }
  }
}

TEST(Rounding, RoundDoubleMatchesCmathRoundingOnRandomValues) {
  // Given seeded random doubles scaled by 2^22
  std::mt19937_64 rng(20240601);
  std::uniform_real_distribution<double> dist(-512.0, 512.0);
  for (int i = 0; i < 20000; ++i) {
    const double v = dist(rng);
    for (Round r : kAllRounds) {
      // When rounded; Then the integer equals the <cmath> rounding
      const std::int64_t got = detail::roundDouble(std::ldexp(v, 22), r, -(std::int64_t{1} << 31),
                                                   (std::int64_t{1} << 31) - 1);
      ASSERT_EQ(static_cast<double>(got), roundRef(std::ldexp(v, 22), r)) << v << name(r);
    }
  }
}

TEST(Rounding, RoundDoubleSaturatesAndTakesNanToZero) {
  const double inf = std::numeric_limits<double>::infinity();
  for (Round r : kAllRounds) {
    EXPECT_EQ(detail::roundDouble(32768.0, r, -32768, 32767), 32767);
    EXPECT_EQ(detail::roundDouble(-1e300, r, -32768, 32767), -32768);
    EXPECT_EQ(detail::roundDouble(inf, r, -32768, 32767), 32767);
    EXPECT_EQ(detail::roundDouble(std::numeric_limits<double>::quiet_NaN(), r, -32768, 32767), 0);
  }
}

TEST(Rounding, RoundingShiftRightMatchesDoubleForEveryInt16AndShift) {
  // Given every int16 value and every shift 1..17 (beyond the width too)
  for (int v = -32768; v < 32768; ++v) {
    const auto raw = static_cast<std::int16_t>(v);
    for (int n = 1; n <= 17; ++n) {
      const double exact = std::ldexp(static_cast<double>(v), -n);
      for (Round r : kAllRounds) {
        // When shifted right with rounding; Then it equals the <cmath> rounding of v / 2^n
        const std::int16_t got = roundingShiftRight(raw, n, r);
        ASSERT_EQ(static_cast<double>(got), roundRef(exact, r)) << v << " >> " << n << name(r);
      }
    }
  }
}

// Integer reference by truncating division, a different method from the code under test.
std::int64_t shiftRef(std::int64_t v, int n, Round r) {
  const std::int64_t d = std::int64_t{1} << n;
  std::int64_t q = v / d;  // toward zero
  std::int64_t rem = v % d;
  if (rem < 0) {  // make it floor
    q -= 1;
    rem += d;
  }
  const std::int64_t half = d / 2;
  switch (r) {
    case Round::kFloor:
      return q;
    case Round::kHalfUp:
      return rem >= half ? q + 1 : q;
    case Round::kHalfEven:
      return (rem > half || (rem == half && (q % 2 != 0))) ? q + 1 : q;
    case Round::kTowardZero:
      return (v < 0 && rem != 0) ? q + 1 : q;
  }
  return 0;
}

TEST(Rounding, RoundingShiftRightOnInt64EdgesAndRandomValues) {
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();
  constexpr std::int64_t k62 = std::int64_t{1} << 62;
  // Given the ends of int64 (hand-derived: columns Floor, HalfUp, HalfEven, TowardZero)
  struct Case {
    std::int64_t v;
    int n;
    std::array<std::int64_t, 4> expected;
  };
  const std::array<Case, 6> cases = {{
      {kMax, 63, {0, 1, 1, 0}},                         // 1 - 2^-63
      {kMin, 63, {-1, -1, -1, -1}},                     // exact
      {kMax, 1, {k62 - 1, k62, k62, k62 - 1}},          // 2^62 - 1/2
      {kMin + 1, 1, {-k62, -k62 + 1, -k62, -k62 + 1}},  // -2^62 + 1/2
      {kMin, 1, {-k62, -k62, -k62, -k62}},              // exact
      {-3, 62, {-1, 0, 0, 0}},                          // tiny negative
  }};
  for (const Case& c : cases) {
    for (std::size_t m = 0; m < kAllRounds.size(); ++m) {
      EXPECT_EQ(roundingShiftRight(c.v, c.n, kAllRounds[m]), c.expected[m])
          << c.v << " >> " << c.n << " " << name(kAllRounds[m]);
    }
  }
  // Unsigned: 2^64 - 1 >> 1 = 2^63 - 1/2
  constexpr std::uint64_t kU = std::numeric_limits<std::uint64_t>::max();
  EXPECT_EQ(roundingShiftRight(kU, 1, Round::kFloor), kU >> 1);
  EXPECT_EQ(roundingShiftRight(kU, 1, Round::kHalfUp), std::uint64_t{1} << 63);
  EXPECT_EQ(roundingShiftRight(kU, 1, Round::kHalfEven), std::uint64_t{1} << 63);
  EXPECT_EQ(roundingShiftRight(kU, 1, Round::kTowardZero), kU >> 1);
  EXPECT_EQ(roundingShiftRight(kU, 63, Round::kHalfUp), 2U);
  // Given seeded random int64 and shifts; Then it matches the division-based reference
  std::mt19937_64 rng(7);
  for (int i = 0; i < 20000; ++i) {
    const auto v = static_cast<std::int64_t>(rng());
    const int n = 1 + static_cast<int>(rng() % 62);
    for (Round r : kAllRounds) {
      ASSERT_EQ(roundingShiftRight(v, n, r), shiftRef(v, n, r)) << v << " >> " << n << name(r);
    }
  }
}

TEST(Rounding, SaturateCastClampsToTheTargetType) {
  EXPECT_EQ(saturateCast<std::int16_t>(std::int64_t{40000}), 32767);
  EXPECT_EQ(saturateCast<std::int16_t>(std::int64_t{-40000}), -32768);
  EXPECT_EQ(saturateCast<std::int16_t>(-1234), -1234);
  EXPECT_EQ(saturateCast<std::uint8_t>(-1), 0);
  EXPECT_EQ(saturateCast<std::uint8_t>(256U), 255);
  EXPECT_EQ(saturateCast<std::int32_t>(std::numeric_limits<std::uint64_t>::max()),
            std::numeric_limits<std::int32_t>::max());
  EXPECT_EQ(saturateCast<std::uint64_t>(std::numeric_limits<std::int64_t>::min()), 0U);
  EXPECT_EQ(saturateCast<std::int64_t>(std::numeric_limits<std::uint64_t>::max()),
            std::numeric_limits<std::int64_t>::max());
}

}  // namespace
}  // namespace smx::algo
