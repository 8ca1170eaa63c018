#include "smx/algo/fixed_math.hpp"

#include <array>
#include <bit>
#include <cstdint>
#include <numbers>

// Per-frame kernels: integer instructions only (tests/static disassembles this object). The
// tables are built by consteval functions in double, which therefore never reach the object file;
// their accuracy is checked by the tests against libm, not trusted.

namespace smx::algo {
namespace {

// ---- Compile-time reference functions (double, consteval: no run-time code) -------------------

// Taylor series; |x| <= π/2 + 0.01, where 30 terms are far below double precision.
consteval double sinSeries(double x) {
  double term = x;
  double sum = x;
  for (int n = 1; n < 30; ++n) {
    term *= -x * x / static_cast<double>((2 * n) * (2 * n + 1));
    sum += term;
  }
  return sum;
}

consteval double sqrtNewton(double v) {
  double r = v > 1.0 ? v : 1.0;
  for (int i = 0; i < 200; ++i) {
    r = 0.5 * (r + v / r);
  }
  return r;
}

// x in [0, 1]. Two half-angle steps, atan(x) = 2 atan(x / (1 + sqrt(1 + x²))), bring the
// argument below tan(π/16) ≈ 0.2, where 40 Taylor terms are far below double precision.
consteval double atanSeries(double x) {
  double y = x;
  for (int k = 0; k < 2; ++k) {
    y = y / (1.0 + sqrtNewton(1.0 + y * y));
  }
  double power = y;
  double sum = 0.0;
  for (int n = 0; n < 40; ++n) {
    const double term = power / static_cast<double>(2 * n + 1);
    sum += (n % 2 == 0) ? term : -term;
    power *= y * y;
  }
  return 4.0 * sum;
}

consteval std::int64_t nearest(double v) {
  return detail::roundDouble(v, Round::kHalfEven, INT64_MIN, INT64_MAX);
}

// ---- Tables --------------------------------------------------------------------------------

// sin over a quarter turn: 256 intervals of 64 binary-angle steps, in Q1.30. One entry past
// π/2 so that interpolation at exactly π/2 (fraction 0) may read index + 1.
constexpr int kSinIntervals = 256;
constexpr int kSinFracBits = 6;  // 16384 steps per quarter / 256 intervals
constexpr auto kSinQ30 = [] consteval {
  std::array<std::int32_t, kSinIntervals + 2> t{};
  for (int i = 0; i < kSinIntervals + 2; ++i) {
    const double x = std::numbers::pi / 2.0 * i / kSinIntervals;
    t[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(nearest(sinSeries(x) * 0x1p30));
  }
  return t;
}
();
static_assert(kSinQ30[0] == 0 && kSinQ30[kSinIntervals] == (1 << 30));

// atan(i / 256) for i in [0, 256] in units of 2^-32 turn (π/4 = 2^29), plus one padding entry
// for t = 1 exactly.
constexpr int kAtanIntervals = 256;
constexpr auto kAtanTurn32 = [] consteval {
  std::array<std::uint32_t, kAtanIntervals + 2> t{};
  for (int i = 0; i < kAtanIntervals + 2; ++i) {
    const double x = static_cast<double>(i > kAtanIntervals ? kAtanIntervals : i) / kAtanIntervals;
    const double turns = atanSeries(x) / (2.0 * std::numbers::pi);
    t[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(nearest(turns * 0x1p32));
  }
  return t;
}
();
static_assert(kAtanTurn32[0] == 0 && kAtanTurn32[kAtanIntervals] == (1U << 29));

// Seed for 2^63 / d, d in [2^31, 2^32), indexed by the 8 bits below the leading one:
// round(2^24 / (256 + i + 1/2)), i.e. the reciprocal at the bucket midpoint, >> 16.
constexpr auto kRecipSeed = [] consteval {
  std::array<std::uint16_t, 256> t{};
  for (int i = 0; i < 256; ++i) {
    t[static_cast<std::size_t>(i)] = static_cast<std::uint16_t>(nearest(0x1p24 / (256.5 + i)));
  }
  return t;
}
();

// Seed for √m · 2^16, m = xn / 2^(bits) in [1/4, 1), indexed by the top 8 bits (64..255):
// the root at the bucket midpoint.
constexpr auto kSqrtSeed = [] consteval {
  std::array<std::uint16_t, 192> t{};
  for (int i = 64; i < 256; ++i) {
    t[static_cast<std::size_t>(i - 64)] =
        static_cast<std::uint16_t>(nearest(sqrtNewton((i + 0.5) / 256.0) * 0x1p16));
  }
  return t;
}
();

// ---- Kernels -------------------------------------------------------------------------------

// sin of p / 16384 quarter turns, p in [0, 16384], as a Q1.14 raw value in [0, 16384].
std::int32_t quarterSin(std::uint32_t p) {
  const std::uint32_t i = p >> kSinFracBits;
  const std::int64_t f = p & ((1U << kSinFracBits) - 1);
  const std::int64_t a = kSinQ30[i];
  const std::int64_t b = kSinQ30[i + 1];
  const std::int64_t acc = (a << kSinFracBits) + (b - a) * f;  // Q1.36, non-negative
  constexpr int kDrop = 30 + kSinFracBits - 14;
  return static_cast<std::int32_t>(roundingShiftRight(acc, kDrop, Round::kHalfUp));
}

std::uint64_t magnitude(std::int64_t v) {
  // Unsigned negation: |INT64_MIN| = 2^63 is representable.
  return v < 0 ? std::uint64_t{0} - static_cast<std::uint64_t>(v) : static_cast<std::uint64_t>(v);
}

BinAngle atan2Magnitudes(std::uint64_t ax, std::uint64_t ay, bool xNegative, bool yNegative) {
  if ((ax | ay) == 0) {
    return BinAngle{0};
  }
  const bool steep = ay > ax;  // octant beyond π/4: use atan(x/y) and reflect about π/4
  std::uint64_t hi = steep ? ay : ax;
  std::uint64_t lo = steep ? ax : ay;
  // Keep hi < 2^32 so that lo << 32 fits; t loses at most 2^-31 (hi >= 2^31 afterwards).
  const int excess = 32 - std::countl_zero(hi);
  if (excess > 0) {
    hi >>= excess;
    lo >>= excess;
  }
  const std::uint64_t t = (lo << 32) / hi;  // Q0.32 in [0, 2^32]
  const auto i = static_cast<std::uint32_t>(t >> 24);
  const std::uint64_t f = t & 0xFFFFFFU;
  const std::uint64_t a = kAtanTurn32[i];
  const std::uint64_t b = kAtanTurn32[i + 1];
  const std::uint64_t turn32 = a + (((b - a) * f) >> 24);  // atan is increasing: b >= a
  // Round once, inside the octant, so that the reflections below are exact.
  auto angle = static_cast<std::uint32_t>(roundingShiftRight(turn32, 16, Round::kHalfUp));
  if (steep) {
    angle = BinAngle::kQuarterTurn - angle;
  }
  if (xNegative) {
    angle = BinAngle::kHalfTurn - angle;
  }
  if (yNegative) {
    angle = BinAngle::kFullTurn - angle;
  }
  return BinAngle{static_cast<std::uint16_t>(angle & 0xFFFFU)};
}

}  // namespace

std::int16_t sin(BinAngle angle) noexcept {
  const std::uint32_t raw = angle.raw;
  const std::uint32_t quadrant = raw >> 14;
  std::uint32_t p = raw & 0x3FFFU;
  if ((quadrant & 1U) != 0) {
    p = BinAngle::kQuarterTurn - p;  // sin(π/2 + r) = sin(π/2 - r)
  }
  const std::int32_t magnitudeQ14 = quarterSin(p);
  const std::int32_t value = (quadrant & 2U) != 0 ? -magnitudeQ14 : magnitudeQ14;
  return static_cast<std::int16_t>(value);
}

std::int16_t cos(BinAngle angle) noexcept {
  return sin(angle + BinAngle{BinAngle::kQuarterTurn});
}

BinAngle atan2(std::int32_t y, std::int32_t x) noexcept {
  return atan2Magnitudes(magnitude(x), magnitude(y), x < 0, y < 0);
}

BinAngle atan2(std::int64_t y, std::int64_t x) noexcept {
  return atan2Magnitudes(magnitude(x), magnitude(y), x < 0, y < 0);
}

Reciprocal reciprocal(std::uint32_t x) noexcept {
  if (x == 0) {
    return Reciprocal{0xFFFFFFFFU, 0};
  }
  const int width = 32 - std::countl_zero(x);  // 1..32
  if ((x & (x - 1)) == 0) {
    return Reciprocal{1U << 31, static_cast<std::uint8_t>(30 + width)};
  }
  // 2^shift / x == 2^63 / d with d = x normalised to [2^31, 2^32) and shift = 31 + width.
  const std::uint64_t d = std::uint64_t{x} << (32 - width);
  constexpr std::uint64_t kOne = std::uint64_t{1} << 63;
  std::uint64_t y = std::uint64_t{kRecipSeed[(d >> 23) & 0xFFU]} << 16;
  for (int step = 0; step < 2; ++step) {
    // e = 2^63 (1 - d·y / 2^63): |e| <= 2^54 after the seed, 2^45 after one step, so e >> 24
    // times y (< 2^32) stays below 2^63. d·y < 2^64 because y < 2^32 throughout (Newton for a
    // reciprocal approaches from below).
    const auto e = static_cast<std::int64_t>(kOne - d * y);
    const auto ys = static_cast<std::int64_t>(y);
    y = static_cast<std::uint64_t>(ys + ((ys * (e >> 24)) >> 39));
  }
  // y is now within a few units of 2^63 / d; the exact residual makes it the nearest integer.
  const auto dSigned = static_cast<std::int64_t>(d);
  auto residual = static_cast<std::int64_t>(kOne - d * y);
  while (2 * residual > dSigned) {
    ++y;
    residual -= dSigned;
  }
  while (2 * residual < -dSigned) {
    --y;
    residual += dSigned;
  }
  return Reciprocal{static_cast<std::uint32_t>(y), static_cast<std::uint8_t>(31 + width)};
}

std::uint32_t divide(std::uint32_t num, std::uint32_t den, Round round) noexcept {
  if (den == 0) {
    return 0xFFFFFFFFU;
  }
  const Reciprocal r = reciprocal(den);
  // The estimate is within 1/4 of num / den (relative error of the mantissa <= 2^-32), so its
  // floor is the quotient or one off either way.
  std::uint64_t q = (std::uint64_t{num} * r.mantissa) >> r.shift;
  auto rem = static_cast<std::int64_t>(num) - static_cast<std::int64_t>(q * den);
  if (rem < 0) {
    --q;
    rem += den;
  } else if (rem >= den) {
    ++q;
    rem -= den;
  }
  bool up = false;
  switch (round) {
    case Round::kFloor:
    case Round::kTowardZero:
      break;
    case Round::kHalfUp:
      up = 2 * rem >= den;
      break;
    case Round::kHalfEven:
      up = 2 * rem > den || (2 * rem == den && (q & 1U) != 0);
      break;
  }
  return static_cast<std::uint32_t>(up ? q + 1 : q);  // <= num since den >= 1
}

std::uint32_t isqrt(std::uint32_t x) noexcept {
  if (x == 0) {
    return 0;
  }
  const int shift = std::countl_zero(x) & ~1;             // even, so √ scales by 2^(shift/2)
  const std::uint32_t xn = x << shift;                    // in [2^30, 2^32)
  const std::uint32_t seed = kSqrtSeed[(xn >> 24) - 64];  // √xn, relative error < 2^-8
  std::uint32_t r = seed >> (shift / 2);                  // >= 1
  r = (r + x / r) >> 1;                                   // Heron: relative error < 2^-17
  // r is now floor(√x) give or take one; settle it exactly (65535² is the largest square that
  // fits, so r is capped there and r + 1 is only squared below it).
  r = r > 0xFFFFU ? 0xFFFFU : r;
  while (r * r > x) {
    --r;
  }
  while (r < 0xFFFFU && (r + 1) * (r + 1) <= x) {
    ++r;
  }
  // Nearest: √x > r + 1/2  <=>  x > r² + r + 1/4  <=>  x - r² > r.
  return x - r * r > r ? r + 1 : r;
}

std::uint64_t isqrt(std::uint64_t x) noexcept {
  if (x == 0) {
    return 0;
  }
  const int shift = std::countl_zero(x) & ~1;
  const std::uint64_t xn = x << shift;  // in [2^62, 2^64)
  const std::uint64_t seed = std::uint64_t{kSqrtSeed[(xn >> 56) - 64]} << 16;
  std::uint64_t r = seed >> (shift / 2);           // >= 1
  r = (r + x / r) >> 1;                            // relative error < 2^-17
  r = (r + x / r) >> 1;                            // < 2^-34
  constexpr std::uint64_t kMaxRoot = 0xFFFFFFFFU;  // largest r with r² < 2^64
  r = r > kMaxRoot ? kMaxRoot : r;
  while (r * r > x) {
    --r;
  }
  while (r < kMaxRoot && (r + 1) * (r + 1) <= x) {
    ++r;
  }
  return x - r * r > r ? r + 1 : r;
}

}  // namespace smx::algo
