#pragma once

// Named rounding for fixed-point integers: how low bits are dropped (Round), a shift that rounds
// as named, a clamping integer conversion, and the one init-time conversion of a double to an
// integer. Fixed-point values are plain integers whose Q format is in their name or comment
// (e.g. a Q1.14 unit vector in an int16); these helpers make every narrowing explicit.

#include <concepts>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

namespace smx::algo {

// How low bits are dropped. Named after the real-number rounding they implement on raw / 2^n.
// The set is what the kernels need: Floor is the bare arithmetic shift, HalfUp the cheap nearest
// (add half, shift; Halide's rounding_shift_right), HalfEven the unbiased nearest for accumulated
// quantities, TowardZero matches C integer division. Nearest-ties-away-from-zero (std::round) is
// left out on purpose: HalfEven is also sign-symmetric and, unlike it, unbiased.
enum class Round : std::uint8_t {
  kFloor,       // toward -infinity
  kHalfUp,      // to nearest, ties toward +infinity
  kHalfEven,    // to nearest, ties to the even neighbour
  kTowardZero,  // truncate the magnitude
};

namespace detail {

// bool and the character types are integers to the language but never raw fixed-point values.
template <class T>
concept PlainInteger = std::integral<T> && !std::same_as<T, bool> && !std::same_as<T, char> &&
                       !std::same_as<T, char8_t> && !std::same_as<T, char16_t> &&
                       !std::same_as<T, char32_t> && !std::same_as<T, wchar_t>;

// Rounds v to an integer under `round`, saturated to [lo, hi] (lo <= 0 <= hi); NaN gives 0.
// Init- and test-time only: this is the one place where a double becomes a raw value.
constexpr std::int64_t roundDouble(double v, Round round, std::int64_t lo, std::int64_t hi) {
  if (!(v >= 0.0) && !(v < 0.0)) {  // NaN (spelled without ==, for -Wfloat-equal)
    return 0;
  }
  // Beyond (lo - 1, hi + 1) every mode saturates; the bounds also keep the int64 cast defined.
  // Both are powers of two (or collapse onto one), so the comparisons are exact.
  if (v >= static_cast<double>(hi) + 1.0) {
    return hi;
  }
  if (v <= static_cast<double>(lo) - 1.0) {
    return lo;
  }
  const auto t = static_cast<std::int64_t>(v);     // truncates; |t| < 2^63 - 1024, so t +- 1 fits
  const double frac = v - static_cast<double>(t);  // exact, in (-1, 1)
  std::int64_t r = t;
  switch (round) {
    case Round::kFloor:
      r = frac < 0.0 ? t - 1 : t;
      break;
    case Round::kHalfUp:
      r = frac >= 0.5 ? t + 1 : (frac < -0.5 ? t - 1 : t);
      break;
    case Round::kHalfEven: {
      // A tie is frac == +-0.5 exactly; it goes to the even neighbour.
      const bool tOdd = (t & 1) != 0;
      if (frac > 0.5 || (frac >= 0.5 && tOdd)) {
        r = t + 1;
      } else if (frac < -0.5 || (frac <= -0.5 && tOdd)) {
        r = t - 1;
      }
      break;
    }
    case Round::kTowardZero:
      break;
  }
  return r < lo ? lo : (r > hi ? hi : r);
}

}  // namespace detail

// Converts an integer to another integer type, clamping to the target range (no wrap, no UB).
template <detail::PlainInteger To, detail::PlainInteger From>
[[nodiscard]] constexpr To saturateCast(From v) noexcept {
  if (std::cmp_less(v, std::numeric_limits<To>::min())) {
    return std::numeric_limits<To>::min();
  }
  if (std::cmp_greater(v, std::numeric_limits<To>::max())) {
    return std::numeric_limits<To>::max();
  }
  return static_cast<To>(v);
}

// value / 2^shift rounded as `round` says, for signed or unsigned raw integers.
// Precondition: 0 <= shift <= 63 (it is computed in 64 bits, so shifts at or beyond the width of
// T are fine and give the rounded tiny quotient: 0, -1 or 1). Never overflows: the rounding
// increment is applied to the already-shifted quotient, which is at most max >> 1.
template <detail::PlainInteger T>
[[nodiscard]] constexpr T roundingShiftRight(T value, int shift, Round round) noexcept {
  if (shift == 0) {
    return value;
  }
  using Wide = std::conditional_t<std::is_signed_v<T>, std::int64_t, std::uint64_t>;
  const Wide v = value;
  const Wide floorQ = v >> shift;  // arithmetic shift for signed (defined since C++20)
  const std::uint64_t mask = (std::uint64_t{1} << shift) - 1;
  const std::uint64_t rem = static_cast<std::uint64_t>(v) & mask;  // v - floorQ * 2^shift
  const std::uint64_t half = std::uint64_t{1} << (shift - 1);
  bool up = false;
  switch (round) {
    case Round::kFloor:
      break;
    case Round::kHalfUp:
      up = rem >= half;
      break;
    case Round::kHalfEven:
      up = rem > half || (rem == half && (floorQ & 1) != 0);
      break;
    case Round::kTowardZero:
      if constexpr (std::is_signed_v<T>) {
        up = v < 0 && rem != 0;
      }
      break;
  }
  return static_cast<T>(up ? floorQ + 1 : floorQ);
}

}  // namespace smx::algo
