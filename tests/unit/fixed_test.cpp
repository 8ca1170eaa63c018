#include "smx/algo/fixed.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <type_traits>

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

// ---- The type -------------------------------------------------------------------------------

static_assert(std::is_same_v<Q<0, 7>::Raw, std::int8_t>);
static_assert(std::is_same_v<Q<0, 15>::Raw, std::int16_t>);  // CMSIS q15_t
static_assert(std::is_same_v<Q<1, 14>::Raw, std::int16_t>);
static_assert(std::is_same_v<Q<1, 13>::Raw, std::int16_t>);  // 15 bits, padded
static_assert(std::is_same_v<Q<0, 31>::Raw, std::int32_t>);  // CMSIS q31_t
static_assert(std::is_same_v<Q<2, 45>::Raw, std::int64_t>);
static_assert(std::is_same_v<Q<0, 63>::Raw, std::int64_t>);
static_assert(sizeof(Q<1, 14>) == 2 && sizeof(Q<0, 31>) == 4);

static_assert(Q<1, 14>::kRawMin == -32768 && Q<1, 14>::kRawMax == 32767);
static_assert(Q<1, 13>::kRawMin == -16384 && Q<1, 13>::kRawMax == 16383);

// The format is in the type: nothing converts implicitly, not even explicitly by construction.
using Q15 = Q<0, 15>;
using Q1p14 = Q<1, 14>;
static_assert(!std::is_convertible_v<double, Q1p14>);
static_assert(!std::is_convertible_v<float, Q1p14>);
static_assert(!std::is_convertible_v<int, Q1p14>);
static_assert(!std::is_convertible_v<std::int16_t, Q1p14>);
static_assert(!std::is_convertible_v<Q1p14, double>);
static_assert(!std::is_convertible_v<Q1p14, float>);
static_assert(!std::is_convertible_v<Q1p14, int>);
static_assert(!std::is_convertible_v<Q1p14, bool>);
static_assert(!std::is_convertible_v<Q15, Q1p14>);  // other formats need rescale
static_assert(!std::is_constructible_v<Q1p14, double>);
static_assert(!std::is_constructible_v<Q1p14, int>);
static_assert(!std::is_constructible_v<Q1p14, std::int16_t>);
static_assert(!std::is_constructible_v<double, Q1p14>);
static_assert(!std::is_constructible_v<int, Q1p14>);
static_assert(!std::is_constructible_v<Q1p14, Q15>);
static_assert(!std::is_assignable_v<Q1p14&, double>);
static_assert(!std::is_assignable_v<Q1p14&, int>);
static_assert(std::is_trivially_copyable_v<Q1p14>);
// Mixed arithmetic with plain numbers or other formats does not compile. (Inside templates, so
// that an ill-formed expression makes the requires-expression false rather than the program
// ill-formed.)
template <class A, class B>
constexpr bool kCanAdd = requires(A a, B b) {
  a + b;
};
template <class A, class B>
constexpr bool kCanMultiply = requires(A a, B b) {
  a* b;
};
template <class A, class B>
constexpr bool kCanCompareEqual = requires(A a, B b) {
  a == b;
};
template <class A, class B>
constexpr bool kCanCompareLess = requires(A a, B b) {
  a < b;
};
template <class To, class From>
constexpr bool kCanStaticCast = requires(From f) {
  static_cast<To>(f);
};
template <class A, class B>
constexpr bool kCanAddSat = requires(A a, B b) {
  addSat(a, b);
};
template <class T>
constexpr bool kCanShiftWithoutRounding = requires(T v) {
  roundingShiftRight(v, 1);
};

static_assert(!kCanAdd<Q1p14, int> && !kCanAdd<int, Q1p14> && !kCanAdd<Q1p14, double>);
static_assert(!kCanMultiply<Q1p14, double> && !kCanMultiply<double, Q1p14>);
static_assert(!kCanMultiply<Q1p14, int> && !kCanMultiply<float, Q1p14>);
static_assert(!kCanCompareEqual<Q1p14, int> && !kCanCompareLess<Q1p14, double>);
static_assert(!kCanAdd<Q1p14, Q15> && !kCanCompareEqual<Q1p14, Q15>);
static_assert(!kCanStaticCast<double, Q1p14> && !kCanStaticCast<int, Q1p14>);
static_assert(!kCanStaticCast<Q1p14, double> && !kCanStaticCast<Q1p14, std::int16_t>);
static_assert(!kCanAddSat<Q1p14, Q15>);
static_assert(!kCanShiftWithoutRounding<std::int32_t>);  // the rounding is always named
// The positive controls: the same detectors do see the operations that exist.
static_assert(kCanAdd<Q1p14, Q1p14> && kCanMultiply<Q1p14, Q15> && kCanAddSat<Q15, Q15>);
static_assert(kCanCompareLess<Q1p14, Q1p14> && kCanStaticCast<Q1p14, Q1p14>);
static_assert(kCanMultiply<Q<31, 0>, Q<31, 0>>);  // -> Q<63, 0>, the widest format

// Widening results have the documented formats.
static_assert(std::is_same_v<decltype(Q15{} * Q15{}), Q<1, 30>>);
static_assert(std::is_same_v<decltype(Q1p14{} * Q15{}), Q<2, 29>>);
static_assert(std::is_same_v<decltype(Q15{} + Q15{}), Q<1, 15>>);
static_assert(std::is_same_v<decltype(Q15{} - Q15{}), Q<1, 15>>);
static_assert(std::is_same_v<decltype(-Q15{}), Q<1, 15>>);

// Everything is usable at compile time.
static_assert(Q15::fromDouble(0.5, Round::kHalfUp).raw() == 16384);
static_assert(Q1p14::fromInt(1).raw() == 16384);
static_assert((Q15::min() * Q15::min()).raw() == (1 << 30));
static_assert(rescale<Q<1, 6>>(Q1p14::fromInt(1), Round::kFloor).raw() == 64);
static_assert(roundingShiftRight(-3, 1, Round::kHalfEven) == -2);
static_assert(saturateCast<std::int8_t>(300) == 127);

TEST(FixedQ, DefaultIsZeroAndFromRawKeepsTheBits) {
  // Given the default and raw factories
  // Then zero is zero and raw bits go through unchanged, clamped only to a padded format's range
  EXPECT_EQ(Q1p14{}.raw(), 0);
  EXPECT_EQ(Q1p14::fromRaw(-12345).raw(), -12345);
  EXPECT_EQ(Q1p14::fromRaw(std::numeric_limits<std::int16_t>::min()).raw(), -32768);
  EXPECT_EQ((Q<1, 13>::fromRaw(20000).raw()), 16383);
  EXPECT_EQ((Q<1, 13>::fromRaw(-20000).raw()), -16384);
  EXPECT_DOUBLE_EQ(Q1p14::fromRaw(-8192).toDouble(), -0.5);
}

TEST(FixedQ, FromDoubleRoundsHalvesAsEachModeSays) {
  // Given values exactly halfway (and not halfway) between two raw steps of Q<3, 4>
  // When converted with each rounding mode
  // Then the raw value is the hand-derived one (columns: Floor, HalfUp, HalfEven, TowardZero)
  struct Case {
    double lsb;  // value in units of 2^-4
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
      const auto q = Q<3, 4>::fromDouble(c.lsb / 16.0, kAllRounds[m]);
      EXPECT_EQ(q.raw(), c.expected[m]) << c.lsb << " LSB, " << name(kAllRounds[m]);
    }
  }
}

TEST(FixedQ, FromDoubleMatchesCmathRoundingOnRandomValues) {
  // Given seeded random doubles inside the range of Q<9, 22>
  std::mt19937_64 rng(20240601);
  std::uniform_real_distribution<double> dist(-512.0, 512.0);
  for (int i = 0; i < 20000; ++i) {
    const double v = dist(rng);
    for (Round r : kAllRounds) {
      // When converted; Then the raw value equals the <cmath> rounding of v * 2^22
      const auto q = Q<9, 22>::fromDouble(v, r);
      ASSERT_EQ(static_cast<double>(q.raw()), roundRef(std::ldexp(v, 22), r)) << v << name(r);
    }
  }
}

TEST(FixedQ, FromDoubleSaturatesAtBothEnds) {
  // Given values at and beyond the range, infinities and NaN
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Round r : kAllRounds) {
    // Then +1 saturates to max in Q0.15, -1 is exact, beyond clamps, NaN is 0
    EXPECT_EQ(Q15::fromDouble(1.0, r).raw(), 32767);
    EXPECT_EQ(Q15::fromDouble(-1.0, r).raw(), -32768);
    EXPECT_EQ(Q15::fromDouble(-1.0001, r).raw(), -32768);
    EXPECT_EQ(Q15::fromDouble(1e300, r).raw(), 32767);
    EXPECT_EQ(Q15::fromDouble(-1e300, r).raw(), -32768);
    EXPECT_EQ(Q15::fromDouble(inf, r).raw(), 32767);
    EXPECT_EQ(Q15::fromDouble(-inf, r).raw(), -32768);
    EXPECT_EQ(Q15::fromDouble(nan, r).raw(), 0);
    // 64-bit formats: bounds are not exact doubles, the saturation still is
    EXPECT_EQ((Q<0, 63>::fromDouble(1.0, r).raw()), std::numeric_limits<std::int64_t>::max());
    EXPECT_EQ((Q<0, 63>::fromDouble(-1.0, r).raw()), std::numeric_limits<std::int64_t>::min());
    EXPECT_EQ((Q<0, 63>::fromDouble(0.5, r).raw()), std::int64_t{1} << 62);
    EXPECT_EQ((Q<63, 0>::fromDouble(1e19, r).raw()), std::numeric_limits<std::int64_t>::max());
    EXPECT_EQ((Q<63, 0>::fromDouble(-1e19, r).raw()), std::numeric_limits<std::int64_t>::min());
  }
  // Just inside the top: 1 - 2^-16 is half a step below max, rounding decides
  EXPECT_EQ(Q15::fromDouble(1.0 - 0x1p-16, Round::kHalfUp).raw(), 32767);
  EXPECT_EQ(Q15::fromDouble(1.0 - 0x1p-16, Round::kHalfEven).raw(), 32767);  // saturated
  EXPECT_EQ(Q15::fromDouble(-1.0 - 0x1p-16, Round::kTowardZero).raw(), -32768);
}

TEST(FixedQ, FromIntSaturates) {
  // Given integers of several types around the integer range [-2, 1] of Q<1, 14>
  // Then inside it they are exact, outside they clamp
  EXPECT_EQ(Q1p14::fromInt(1).raw(), 16384);
  EXPECT_EQ(Q1p14::fromInt(-2).raw(), -32768);
  EXPECT_EQ(Q1p14::fromInt(2).raw(), 32767);
  EXPECT_EQ(Q1p14::fromInt(-3).raw(), -32768);
  EXPECT_EQ(Q1p14::fromInt(std::numeric_limits<std::int64_t>::max()).raw(), 32767);
  EXPECT_EQ(Q1p14::fromInt(std::numeric_limits<std::int64_t>::min()).raw(), -32768);
  EXPECT_EQ(Q1p14::fromInt(std::numeric_limits<std::uint64_t>::max()).raw(), 32767);
  EXPECT_EQ(Q1p14::fromInt(0U).raw(), 0);
  EXPECT_EQ(Q15::fromInt(1).raw(), 32767);
  EXPECT_EQ(Q15::fromInt(-1).raw(), -32768);
  EXPECT_EQ((Q<0, 63>::fromInt(-1).raw()), std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ((Q<0, 63>::fromInt(1).raw()), std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ((Q<63, 0>::fromInt(std::numeric_limits<std::int64_t>::min()).raw()),
            std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ((Q<63, 0>::fromInt(std::numeric_limits<std::uint64_t>::max()).raw()),
            std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ((Q<7, 8>::fromInt(-100).toDouble()), -100.0);
}

TEST(FixedQ, WideningMultiplyIsExactAtTheExtremes) {
  // Given the extreme values of several formats
  // When multiplied
  // Then the widened product is exact (hand-derived raw values), never saturated
  EXPECT_EQ((Q15::min() * Q15::min()).raw(), 1 << 30);  // -1 * -1 = +1 in Q1.30
  EXPECT_EQ((Q15::min() * Q15::min()).toDouble(), 1.0);
  EXPECT_EQ((Q15::max() * Q15::max()).raw(), 32767 * 32767);
  EXPECT_EQ((Q15::min() * Q15::max()).raw(), -32768 * 32767);
  EXPECT_EQ((Q1p14::min() * Q1p14::min()).toDouble(), 4.0);  // Q<3, 28>
  const auto big = Q<0, 31>::min() * Q<0, 31>::min();        // Q<1, 62>
  EXPECT_EQ(big.raw(), std::int64_t{1} << 62);
  const auto bigMixed = Q<0, 31>::min() * Q<0, 31>::max();
  EXPECT_EQ(bigMixed.raw(), -(std::int64_t{1} << 62) + (std::int64_t{1} << 31));
  const auto bigMax = Q<0, 31>::max() * Q<0, 31>::max();
  EXPECT_EQ(bigMax.raw(), (std::int64_t{1} << 62) - (std::int64_t{1} << 32) + 1);
  EXPECT_EQ((Q<31, 0>::min() * Q<31, 0>::min()).raw(), std::int64_t{1} << 62);  // Q<63, 0>
  EXPECT_EQ((Q<62, 0>::min() * Q<0, 0>::min()).raw(), std::int64_t{1} << 62);   // Q<63, 0>
}

TEST(FixedQ, WideningMultiplyIsExactForEveryInt8Pair) {
  // Given every pair of Q<0, 7> and Q<3, 4> values
  for (int a = -128; a < 128; ++a) {
    for (int b = -128; b < 128; ++b) {
      const auto qa = Q<0, 7>::fromRaw(static_cast<std::int8_t>(a));
      const auto qb = Q<3, 4>::fromRaw(static_cast<std::int8_t>(b));
      // When multiplied; Then the double value equals the (exact) double product
      ASSERT_EQ((qa * qb).toDouble(), (a / 128.0) * (b / 16.0)) << a << " * " << b;
    }
  }
}

TEST(FixedQ, AdditionWidensAndSaturatingAdditionClamps) {
  // Given extreme Q0.15 values
  // Then + and - widen by one integer bit and are exact
  EXPECT_EQ((Q15::max() + Q15::max()).raw(), 65534);
  EXPECT_EQ((Q15::min() + Q15::min()).raw(), -65536);
  EXPECT_EQ((Q15::max() - Q15::min()).raw(), 65535);
  EXPECT_EQ((-Q15::min()).raw(), 32768);
  EXPECT_EQ((-Q15::min()).toDouble(), 1.0);
  // And addSat / subSat stay in the format, clamping at both ends
  const auto half = Q15::fromDouble(0.5, Round::kHalfEven);
  EXPECT_EQ(addSat(half, half).raw(), 32767);
  EXPECT_EQ(addSat(Q15::min(), Q15::fromRaw(-1)).raw(), -32768);
  EXPECT_EQ(addSat(half, Q15::fromRaw(-1)).raw(), 16383);
  EXPECT_EQ(subSat(Q15::min(), half).raw(), -32768);
  EXPECT_EQ(subSat(half, Q15::min()).raw(), 32767);
  EXPECT_EQ(subSat(Q15{}, Q15::min()).raw(), 32767);
  EXPECT_EQ(subSat(half, half).raw(), 0);
  // 64-bit formats cannot be widened; their saturating sums must still not overflow
  using Q63 = Q<63, 0>;
  EXPECT_EQ(addSat(Q63::max(), Q63::fromInt(1)), Q63::max());
  EXPECT_EQ(addSat(Q63::min(), Q63::fromInt(-1)), Q63::min());
  EXPECT_EQ(addSat(Q63::max(), Q63::min()).raw(), -1);
  EXPECT_EQ(subSat(Q63::min(), Q63::fromInt(1)), Q63::min());
  EXPECT_EQ(subSat(Q63::fromInt(0), Q63::min()), Q63::max());
  // Padded formats saturate at the format range, not the storage range
  using Q13 = Q<1, 13>;
  EXPECT_EQ(addSat(Q13::max(), Q13::max()).raw(), 16383);
  EXPECT_EQ(subSat(Q13::min(), Q13::max()).raw(), -16384);
}

TEST(FixedQ, ComparisonsOrderByValue) {
  const auto a = Q1p14::fromDouble(-1.5, Round::kHalfEven);
  const auto b = Q1p14::fromDouble(0.25, Round::kHalfEven);
  EXPECT_LT(a, b);
  EXPECT_GT(b, a);
  EXPECT_LE(a, a);
  EXPECT_EQ(b, Q1p14::fromRaw(4096));
  EXPECT_NE(a, b);
  EXPECT_LT(Q1p14::min(), Q1p14::max());
}

TEST(FixedQ, RoundingShiftRightMatchesDoubleForEveryInt16AndShift) {
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

TEST(FixedQ, RoundingShiftRightOnInt64EdgesAndRandomValues) {
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

TEST(FixedQ, SaturateCastClampsToTheTargetType) {
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

TEST(FixedQ, RescaleRoundsAndSaturates) {
  // Given a value halfway between two Q<1, 14> steps, of either sign
  const auto pos = Q<1, 30>::fromRaw((5 << 16) + (1 << 15));  // 5.5 LSB of Q1.14
  const auto neg = Q<1, 30>::fromRaw(-(5 << 16) - (1 << 15));
  // When narrowed with each mode; Then the rounding is the named one
  EXPECT_EQ(rescale<Q1p14>(pos, Round::kFloor).raw(), 5);
  EXPECT_EQ(rescale<Q1p14>(pos, Round::kHalfUp).raw(), 6);
  EXPECT_EQ(rescale<Q1p14>(pos, Round::kHalfEven).raw(), 6);
  EXPECT_EQ(rescale<Q1p14>(pos, Round::kTowardZero).raw(), 5);
  EXPECT_EQ(rescale<Q1p14>(neg, Round::kFloor).raw(), -6);
  EXPECT_EQ(rescale<Q1p14>(neg, Round::kHalfUp).raw(), -5);
  EXPECT_EQ(rescale<Q1p14>(neg, Round::kHalfEven).raw(), -6);
  EXPECT_EQ(rescale<Q1p14>(neg, Round::kTowardZero).raw(), -5);
  EXPECT_EQ((rescale<Q1p14, Round::kHalfUp>(neg).raw()), -5);
  // Saturation at both ends when integer bits are lost
  const auto big = Q<7, 8>::fromInt(100);
  EXPECT_EQ(rescale<Q15>(big, Round::kHalfEven), Q15::max());
  EXPECT_EQ(rescale<Q15>(Q<7, 8>::fromInt(-100), Round::kHalfEven), Q15::min());
  EXPECT_EQ(rescale<Q1p14>(Q<3, 28>::fromDouble(1.99999, Round::kHalfEven), Round::kHalfUp),
            Q1p14::max());  // rounds up to 2.0, which does not fit
  EXPECT_EQ((rescale<Q<0, 3>>(Q<62, 0>::min(), Round::kFloor)), (Q<0, 3>::min()));
  EXPECT_EQ((rescale<Q<1, 61>>(Q<62, 0>::max(), Round::kFloor)), (Q<1, 61>::max()));
  // Gaining fractional bits is exact
  EXPECT_EQ((rescale<Q<1, 30>>(Q1p14::fromRaw(-12345), Round::kFloor).raw()), -12345 * 65536);
  EXPECT_EQ((rescale<Q<2, 61>>(Q1p14::min(), Round::kFloor).raw()), -(std::int64_t{1} << 62));
}

// Reference for rescale: the <cmath> rounding of x · 2^To::kFracBits, clamped to To's range.
template <QFormat To>
double rescaleRef(double x, Round r) {
  const double ref = roundRef(std::ldexp(x, To::kFracBits), r);
  return std::clamp(ref, static_cast<double>(To::kRawMin), static_cast<double>(To::kRawMax));
}

template <QFormat To, int I, int F>
void expectRescaleMatchesRef(Q<I, F> x) {
  for (Round r : kAllRounds) {
    ASSERT_EQ(static_cast<double>(rescale<To>(x, r).raw()), rescaleRef<To>(x.toDouble(), r))
        << "raw " << x.raw() << " to Q<" << To::kIntBits << ", " << To::kFracBits << "> "
        << name(r);
  }
}

TEST(FixedQ, RescaleMatchesDoubleOnRandomValues) {
  // Given seeded random Q<5, 26> values
  std::mt19937 rng(99);
  for (int i = 0; i < 20000; ++i) {
    const auto x = Q<5, 26>::fromRaw(static_cast<std::int32_t>(rng()));
    // When narrowed to a padded (12-bit) and a full (16-bit) format
    // Then it is the clamped <cmath> rounding of x · 2^F
    expectRescaleMatchesRef<Q<2, 9>>(x);
    expectRescaleMatchesRef<Q<1, 14>>(x);
    expectRescaleMatchesRef<Q<0, 31>>(x);
  }
}

TEST(FixedQ, RescaleMatchesDoubleForEveryInt16) {
  // Given every Q<7, 8> value
  for (int v = -32768; v < 32768; ++v) {
    const auto x = Q<7, 8>::fromRaw(static_cast<std::int16_t>(v));
    // When given more fractional bits (losing integer bits: saturation) or fewer
    // Then it is the clamped <cmath> rounding of x · 2^F
    expectRescaleMatchesRef<Q<1, 14>>(x);
    expectRescaleMatchesRef<Q<1, 13>>(x);  // padded
    expectRescaleMatchesRef<Q<3, 28>>(x);
    expectRescaleMatchesRef<Q<2, 3>>(x);  // padded int8
    expectRescaleMatchesRef<Q<0, 7>>(x);
  }
}

}  // namespace
}  // namespace smx::algo
