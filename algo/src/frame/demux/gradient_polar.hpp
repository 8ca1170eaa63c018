#pragma once

// The doubled angle and the magnitude of a gradient, for histogramTiles(), without a division:
// atan2() and isqrt() divide once each and settle their last bit in loops, which made them most
// of that stage's time. Here the ratio t = lo / hi of the octant-reduced gradient comes from an
// interpolated reciprocal table, and atan t and √(1 + t²) from one interpolated table, so that
// the angle is atan t reflected out of its octant and |g| = hi · √(1 + t²). The tables are built
// at compile time by integer arithmetic. Accuracy (tests/unit/gradient_polar_test.cpp): the
// doubled angle within 0.55 raw units (2^16 per turn) of the exact one, |g| within 0.54.

#include <array>
#include <bit>
#include <cstdint>

namespace smx::algo::demux {

namespace polar_detail {

// 1 / hn for hn = 2^13 + 32 j, j in [0, 256], as 2^44 / hn rounded: in [2^30, 2^31].
inline constexpr int kRecipShift = 44;
inline constexpr auto kRecip = [] {
  std::array<std::uint32_t, 257> table{};
  for (std::uint64_t j = 0; j < table.size(); ++j) {
    const std::uint64_t hn = (std::uint64_t{1} << 13) + 32 * j;
    table[j] = static_cast<std::uint32_t>(((std::uint64_t{1} << kRecipShift) + hn / 2) / hn);
  }
  return table;
}();

// The nearest integer to √v.
constexpr std::uint64_t nearestRoot(std::uint64_t v) {
  std::uint64_t r = 0;
  for (std::uint64_t bit = std::uint64_t{1} << 31; bit != 0; bit >>= 1) {
    if ((r + bit) * (r + bit) <= v) {
      r += bit;
    }
  }
  return v - r * r > r ? r + 1 : r;  // √v > r + 1/2  <=>  v > r² + r (integers)
}

// atan(p / 256) in units of 2^-40 rad by Euler's series, atan x = Σ T_n with
// T_0 = x / (1 + x²), T_n = T_(n−1) · 2n / (2n + 1) · x² / (1 + x²): every term at most half
// the one before for x <= 1, so about 40 terms reach 0. Each term is truncated: < 2^-33 rad in all.
constexpr std::uint64_t atanQ40(std::uint64_t p) {
  constexpr std::uint64_t kQ2 = std::uint64_t{256} * 256;
  const std::uint64_t den = kQ2 + p * p;
  std::uint64_t term = ((p * 256) << 40) / den;  // < 2^39
  std::uint64_t sum = 0;
  for (std::uint64_t n = 1; term != 0; ++n) {
    sum += term;
    term = term * (2 * n) / (2 * n + 1);
    term = term * (p * p) / den;  // term < 2^40, p² <= 2^16
  }
  return sum;
}

// Per t = i / 256, i in [0, 256] plus one entry for interpolation at t = 1 exactly: atan t in
// units of 2^-32 turn (π/4 = 2^29) and √(1 + t²) in Q1.30.
struct PolarEntry {
  std::uint32_t atanTurn32;
  std::uint32_t rootQ30;
};
inline constexpr auto kPolar = [] {
  // turn32 = rad · 2^32 / 2π = radQ40 / (2^9 π) = radQ40 · 2^20 / (π · 2^29).
  constexpr std::uint64_t kPiQ29 = 1686629713;  // π · 2^29 = 1 686 629 713.06
  std::array<PolarEntry, 258> table{};
  for (std::uint64_t i = 0; i < table.size(); ++i) {
    const std::uint64_t p = i > 256 ? 256 : i;
    const std::uint64_t radQ40 = atanQ40(p);
    table[i].atanTurn32 = static_cast<std::uint32_t>(((radQ40 << 20) + kPiQ29 / 2) / kPiQ29);
    // √(1 + p²/2^16) · 2^30 = √((2^16 + p²) · 2^44)
    table[i].rootQ30 = static_cast<std::uint32_t>(nearestRoot(((1U << 16) + p * p) << 44));
  }
  return table;
}();
static_assert(kPolar[0].atanTurn32 == 0 && kPolar[256].atanTurn32 == (1U << 29));
static_assert(kPolar[0].rootQ30 == (1U << 30) && kPolar[256].rootQ30 == 1518500250);  // √2 · 2^30
static_assert(kRecip[0] == (1U << 31) && kRecip[256] == (1U << 30));

}  // namespace polar_detail

struct GradientPolar {
  std::uint16_t angle2;  // the doubled angle of (gx, gy), BinAngle raw
  std::int32_t weight;   // |g| rounded
};

// For |gx|, |gy| < 2^14 ((0, 0) gives angle 0, weight 0).
[[nodiscard]] inline GradientPolar gradientPolar(std::int32_t gx, std::int32_t gy) {
  using polar_detail::kPolar;
  using polar_detail::kRecip;
  const auto ax = static_cast<std::uint32_t>(gx < 0 ? -gx : gx);
  const auto ay = static_cast<std::uint32_t>(gy < 0 ? -gy : gy);
  const bool steep = ay > ax;  // beyond π/4: atan(x / y), reflected about π/4 below
  const std::uint32_t hi = steep ? ay : ax;
  const std::uint32_t lo = steep ? ax : ay;
  // hi normalised to [2^13, 2^14) (hi = 0 as 1: lo is 0 then, and so is the weight).
  const std::uint32_t hi1 = hi | static_cast<std::uint32_t>(hi == 0);
  const int shift = 14 - static_cast<int>(std::bit_width(hi1));
  const std::uint32_t hn = hi1 << shift;
  const std::uint32_t ln = lo << shift;
  // 2^44 / hn between table entries 32 apart: the chord lies above 1 / x, by < 2^-18 relative.
  const std::uint32_t j = (hn >> 5) - 256;
  const std::uint32_t jf = hn & 31U;
  const std::uint32_t recip = kRecip[j] - (((kRecip[j] - kRecip[j + 1]) * jf) >> 5);
  // t = ln / hn in Q0.24; the chord may put lo = hi a hair above 1.
  std::uint64_t t = (std::uint64_t{ln} * recip) >> (polar_detail::kRecipShift - 24);
  t = t > (1U << 24) ? (1U << 24) : t;
  const auto i = static_cast<std::size_t>(t >> 16);
  const std::uint64_t f = t & 0xFFFFU;
  const polar_detail::PolarEntry a = kPolar[i];
  const polar_detail::PolarEntry b = kPolar[i + 1];
  const std::uint64_t turn32 = a.atanTurn32 + (((b.atanTurn32 - a.atanTurn32) * f) >> 16);
  const std::uint64_t root = a.rootQ30 + (((b.rootQ30 - a.rootQ30) * f) >> 16);
  // The doubled octant angle in [0, 2^14], rounded once; the reflections are exact on doubled
  // angles: about π/4 (steep) it is π − 2θ, about either axis −2θ.
  auto angle2 = static_cast<std::uint32_t>((turn32 + (1U << 14)) >> 15);
  angle2 = steep ? (1U << 15) - angle2 : angle2;
  angle2 = (gx < 0) != (gy < 0) ? 0U - angle2 : angle2;
  const auto weight = static_cast<std::int32_t>((hi * root + (1U << 29)) >> 30);
  return {static_cast<std::uint16_t>(angle2 & 0xFFFFU), weight};
}

}  // namespace smx::algo::demux
