#pragma once

// Integer-only elementary functions for the per-frame path: sin/cos, atan2, reciprocal, division,
// square root. The kernels live in src/frame/fixed_math.cpp and use integer instructions only;
// their tables are computed at compile time. Functions here that take or return double are for
// init time and tests. Measured errors: docs/fixed-point.md, tests/unit/fixed_math_test.cpp.

#include <cstdint>
#include <limits>
#include <numbers>

#include "smx/algo/rounding.hpp"

namespace smx::algo {

// An angle in binary units: raw / 65536 of a full turn, wrapping naturally in uint16 arithmetic.
// Doubled-angle friendly: 2θ is a wrapping shift, so orientations (θ and θ + π the same) can be
// carried as 2θ, averaged as vectors, and halved back at the end.
struct BinAngle {
  static constexpr std::uint32_t kFullTurn = 65536;
  static constexpr std::uint16_t kQuarterTurn = 16384;
  static constexpr std::uint16_t kHalfTurn = 32768;

  std::uint16_t raw = 0;

  // 2θ, wrapping: exact.
  [[nodiscard]] constexpr BinAngle doubled() const noexcept {
    return {static_cast<std::uint16_t>(raw << 1)};
  }
  // The half angle in [0, π), i.e. the orientation whose double is this angle (the other root,
  // +π, is the same orientation). Drops the lowest bit: the result is θ/2 rounded down, at most
  // 1 LSB (2π / 65536) below the exact half.
  [[nodiscard]] constexpr BinAngle halved() const noexcept {
    return {static_cast<std::uint16_t>(raw >> 1)};
  }

  friend constexpr BinAngle operator+(BinAngle a, BinAngle b) noexcept {
    return {static_cast<std::uint16_t>(a.raw + b.raw)};
  }
  friend constexpr BinAngle operator-(BinAngle a, BinAngle b) noexcept {
    return {static_cast<std::uint16_t>(a.raw - b.raw)};
  }
  friend constexpr BinAngle operator-(BinAngle a) noexcept {
    return {static_cast<std::uint16_t>(-a.raw)};
  }
  friend constexpr bool operator==(BinAngle, BinAngle) = default;

  // Init- and test-time only: nearest binary angle (ties to even), wrapped into [0, 2π); NaN
  // gives 0. Meant for angles of a few turns: far out the double no longer resolves 1 LSB.
  [[nodiscard]] static constexpr BinAngle fromDegrees(double degrees) noexcept {
    return fromTurns(degrees / 360.0);
  }
  [[nodiscard]] static constexpr BinAngle fromRadians(double radians) noexcept {
    return fromTurns(radians / kTwoPi);
  }
  // Init- and test-time only: the angle in [0, 360) degrees / [0, 2π) radians.
  [[nodiscard]] constexpr double toDegrees() const noexcept {
    return static_cast<double>(raw) * (360.0 / kFullTurn);
  }
  [[nodiscard]] constexpr double toRadians() const noexcept {
    return static_cast<double>(raw) * (kTwoPi / kFullTurn);
  }

 private:
  static constexpr double kTwoPi = 2.0 * std::numbers::pi;

  static constexpr BinAngle fromTurns(double turns) noexcept {
    const std::int64_t n = detail::roundDouble(turns * kFullTurn, Round::kHalfEven,
                                               std::numeric_limits<std::int64_t>::min(),
                                               std::numeric_limits<std::int64_t>::max());
    return {static_cast<std::uint16_t>(static_cast<std::uint64_t>(n) & 0xFFFFU)};
  }
};

// sin and cos of a binary angle.
//   Input   BinAngle (16 bits per turn).
//   Output  Q1.14 in an int16 (16384 = 1); exactly 0 and +-1 at the multiples of π/2; sin(-a) ==
//   -sin(a) and
//           cos(a) == sin(a + π/2) bit for bit.
//   Method  quarter-wave table, 257 points of sin in Q1.30 (int32), linear interpolation between
//           them on the remaining 6 bits in an int64 accumulator, then one HalfUp rounding of the
//           magnitude to Q1.14. Nothing saturates (|result| <= 16384).
//   Error   <= 0.5 LSB rounding + 0.077 LSB interpolation (h^2/8, h = π/512): bound 0.58 LSB.
[[nodiscard]] std::int16_t sin(BinAngle angle) noexcept;
[[nodiscard]] std::int16_t cos(BinAngle angle) noexcept;

// Angle of the vector (x, y), as std::atan2(y, x), wrapped into [0, 2π) as a BinAngle.
//   Input   int32 or int64 (the doubled-angle structure tensor feeds gx²−gy² and 2·gx·gy as int64);
//           the whole range including INT_MIN.
//   Output  BinAngle; atan2(0, 0) is defined as 0 (as std::atan2(+0, +0)).
//   Method  octant reduction on magnitudes (uint64) to t = min/max in Q0.32 by one 64/64-bit
//           integer division (udiv; int64 inputs first shifted so that max < 2^32, losing at most
//           2^-31 of t); atan on [0, 1] from a 257-point table in units of 2^-32 turn with linear
//           interpolation on the low 24 bits of t; one HalfUp rounding to 16 bits inside the
//           octant, then exact reflections. Axes and diagonals are exact; the result is
//           symmetric under x and y sign flips bit for bit.
//   Error   <= 0.5 LSB rounding + 0.013 LSB interpolation + < 0.001 LSB from t: bound 0.52 LSB
//           (1 LSB = 2π / 65536).
[[nodiscard]] BinAngle atan2(std::int32_t y, std::int32_t x) noexcept;
[[nodiscard]] BinAngle atan2(std::int64_t y, std::int64_t x) noexcept;

// 1/x ≈ mantissa · 2^-shift, with mantissa normalised to [2^31, 2^32). a / x is then
// (uint64(a) * mantissa) >> shift (see mulReciprocal), one multiply and one shift per use.
struct Reciprocal {
  std::uint32_t mantissa = 0;
  std::uint8_t shift = 0;  // 31..63
};

// Reciprocal of a uint32.
//   Input   x in [1, 2^32); x = 0 saturates to {0xFFFFFFFF, 0} (≈ 2^32).
//   Output  mantissa = 2^shift / x rounded to nearest (no ties occur), shift = 31 + bit_width(x)
//           for non-powers of two, 30 + bit_width(x) for powers of two (exact, mantissa 2^31).
//   Method  normalise x to d in [2^31, 2^32); 256-entry uint16 seed table of 2^63 / d
//           (relative error < 2^-9); two Newton steps y += y·(2^63 − d·y) / 2^63 with 64-bit
//           products (d·y < 2^64 because Newton for 1/d approaches from below); then the exact
//           residual 2^63 − d·y fixes the last unit, so the mantissa is correctly rounded.
//   Error   |mantissa − 2^shift / x| <= 0.5, i.e. relative error <= 2^-32.
[[nodiscard]] Reciprocal reciprocal(std::uint32_t x) noexcept;

// a / x from a precomputed reciprocal: (a · mantissa) / 2^shift rounded as `round` says.
//   Input   a uint32, r = reciprocal(x).
//   Output  uint32; saturates to UINT32_MAX only with the x = 0 reciprocal (a = 0 still gives 0).
//   Accumulator uint64: a · mantissa < 2^64, no overflow.
//   Error   the unrounded a · mantissa / 2^shift is within a · 0.5 / 2^shift < 0.25 of a / x
//           (exact for powers of two), so the result is within 0.75 LSB of a / x for the
//           nearest modes and in (a/x − 1.25, a/x + 0.25) for Floor/TowardZero. divide() is exact.
[[nodiscard]] constexpr std::uint32_t mulReciprocal(std::uint32_t a, Reciprocal r,
                                                    Round round) noexcept {
  const std::uint64_t product = std::uint64_t{a} * r.mantissa;
  return saturateCast<std::uint32_t>(roundingShiftRight(product, r.shift, round));
}

// Quotient num / den, exactly rounded as `round` says (unsigned: Floor == TowardZero).
//   Output  uint32 (<= num); den = 0 saturates to UINT32_MAX, for any num.
//   Method  reciprocal(den); one 32x32->64 multiply gives an estimate within 1 of the quotient;
//           the exact remainder num − q·den (int64) corrects it and decides the rounding.
//           No divide instruction.
//   Error   none.
[[nodiscard]] std::uint32_t divide(std::uint32_t num, std::uint32_t den, Round round) noexcept;

// Square root rounded to nearest: the integer r minimising |r − √x| (ties cannot occur:
// (r + 1/2)² is never an integer). isqrt(uint32) <= 65536 and isqrt(uint64) <= 2^32, hence the
// result types.
//   Method  normalise by an even shift; 192-entry uint16 seed table of √ indexed by the top 8
//           bits (relative error < 2^-8); Heron steps r = (r + x / r) / 2 on the hardware
//           integer divider (one for uint32, two for uint64: relative error < 2^-17, < 2^-34);
//           then exact correction against r² and (r + 1)² in the input width (r capped so that
//           nothing overflows) and the rounding test x − r² > r.
//   Error   none beyond the rounding: |r − √x| < 0.5.
[[nodiscard]] std::uint32_t isqrt(std::uint32_t x) noexcept;
[[nodiscard]] std::uint64_t isqrt(std::uint64_t x) noexcept;

}  // namespace smx::algo
