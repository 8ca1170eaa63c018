#pragma once

// Fixed-point numbers with the format in the type: Q<IntBits, FracBits>.
//
// value = raw / 2^FracBits, raw in [-2^(IntBits+FracBits), 2^(IntBits+FracBits) - 1], stored in
// the smallest signed integer holding 1 + IntBits + FracBits bits. Q<0, 15> is CMSIS q15_t,
// Q<1, 14> is an int16 with range [-2, 2).
//
// Rules (see docs/fixed-point.md):
//   - No implicit conversion to or from float, double or any integer; values come from the named
//     factories fromRaw / fromInt / fromDouble and leave through raw() (or toDouble() in tests).
//   - Widening is the default and exact: a * b is Q<I1+I2+1, F1+F2>, a + b and a - b are Q<I+1, F>.
//   - Narrowing is always spelled out: rescale<To>(x, Round::...), addSat/subSat, saturateCast.
//   - Nothing relies on signed overflow: arithmetic is done in int64 where the result provably
//     fits, and everything else is compared against the bounds before it is formed.

#include <compare>
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

template <int IntBits, int FracBits>
class Q;

namespace detail {

template <int Bits>
using SignedStorage = std::conditional_t<
    Bits <= 8, std::int8_t,
    std::conditional_t<Bits <= 16, std::int16_t,
                       std::conditional_t<Bits <= 32, std::int32_t, std::int64_t>>>;

template <class T>
inline constexpr bool kIsQ = false;
template <int I, int F>
inline constexpr bool kIsQ<Q<I, F>> = true;

// bool and the character types are integers to the language but never raw fixed-point values.
template <class T>
concept PlainInteger = std::integral<T> && !std::same_as<T, bool> && !std::same_as<T, char> &&
                       !std::same_as<T, char8_t> && !std::same_as<T, char16_t> &&
                       !std::same_as<T, char32_t> && !std::same_as<T, wchar_t>;

constexpr double pow2(int n) {
  return static_cast<double>(std::uint64_t{1} << n);
}

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

// True for the Q<I, F> class templates; used to constrain rescale and friends.
template <class T>
concept QFormat = detail::kIsQ<T>;

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

template <int IntBits, int FracBits>
class Q {
  static_assert(IntBits >= 0 && FracBits >= 0, "Q<IntBits, FracBits> needs non-negative bits");
  static_assert(1 + IntBits + FracBits <= 64, "Q format needs more than 64 bits");

 public:
  static constexpr int kIntBits = IntBits;
  static constexpr int kFracBits = FracBits;
  static constexpr int kBits = 1 + IntBits + FracBits;
  using Raw = detail::SignedStorage<kBits>;
  static constexpr Raw kRawMax = static_cast<Raw>((std::uint64_t{1} << (kBits - 1)) - 1);
  static constexpr Raw kRawMin = static_cast<Raw>(-kRawMax - 1);

  // Zero. Kept so that arrays and members of Q can be declared before they are filled.
  constexpr Q() = default;

  // The raw integer as is, clamped to the format's range when the format does not fill its
  // storage (e.g. Q<1, 13> in an int16); for formats that fill it this is the identity.
  [[nodiscard]] static constexpr Q fromRaw(Raw raw) noexcept {
    if constexpr (kBits < std::numeric_limits<Raw>::digits + 1) {
      raw = raw < kRawMin ? kRawMin : (raw > kRawMax ? kRawMax : raw);
    }
    return Q(raw);
  }

  // An integer value, saturated to the format's range.
  template <detail::PlainInteger T>
  [[nodiscard]] static constexpr Q fromInt(T v) noexcept {
    // Integers representable are [-2^IntBits, 2^IntBits - 1]; inside that, v << FracBits fits.
    constexpr std::int64_t kHi = kRawMax >> FracBits;
    constexpr std::int64_t kLo = kRawMin >> FracBits;
    if (std::cmp_greater(v, kHi)) {
      return max();
    }
    if (std::cmp_less(v, kLo)) {
      return min();
    }
    return Q(static_cast<Raw>(static_cast<std::int64_t>(v) << FracBits));
  }

  // Init- and test-time only (uses double): v rounded to the nearest raw step as `round` says,
  // saturated to the range; NaN gives 0.
  [[nodiscard]] static constexpr Q fromDouble(double v, Round round) noexcept {
    return Q(
        static_cast<Raw>(detail::roundDouble(v * detail::pow2(FracBits), round, kRawMin, kRawMax)));
  }

  [[nodiscard]] static constexpr Q max() noexcept { return Q(kRawMax); }
  // The most negative value, -2^IntBits.
  [[nodiscard]] static constexpr Q min() noexcept { return Q(kRawMin); }

  [[nodiscard]] constexpr Raw raw() const noexcept { return raw_; }

  // Host and tests only. Exact while kBits <= 53.
  [[nodiscard]] constexpr double toDouble() const noexcept {
    return static_cast<double>(raw_) / detail::pow2(FracBits);
  }

  // Exact product: Q<I1, F1> * Q<I2, F2> -> Q<I1 + I2 + 1, F1 + F2>. |product| <= 2^(I1 + I2) so
  // it always fits; a format beyond 64 bits fails the static_assert of the result type.
  template <int I2, int F2>
  [[nodiscard]] constexpr auto operator*(Q<I2, F2> rhs) const noexcept {
    using R = Q<IntBits + I2 + 1, FracBits + F2>;
    const std::int64_t lhs = raw_;
    return R(static_cast<typename R::Raw>(lhs * rhs.raw()));
  }

  // Exact sum and difference of one format: one more integer bit, so they cannot overflow.
  // Saturating same-format versions are addSat / subSat below.
  [[nodiscard]] constexpr auto operator+(Q rhs) const noexcept {
    using R = Q<IntBits + 1, FracBits>;
    const std::int64_t lhs = raw_;
    return R(static_cast<typename R::Raw>(lhs + rhs.raw_));
  }
  [[nodiscard]] constexpr auto operator-(Q rhs) const noexcept {
    using R = Q<IntBits + 1, FracBits>;
    const std::int64_t lhs = raw_;
    return R(static_cast<typename R::Raw>(lhs - rhs.raw_));
  }
  // Exact negation: -min() needs one more integer bit.
  [[nodiscard]] constexpr auto operator-() const noexcept {
    using R = Q<IntBits + 1, FracBits>;
    const std::int64_t v = raw_;
    return R(static_cast<typename R::Raw>(-v));
  }

  // Same-format comparisons only; compare other formats after an explicit rescale.
  friend constexpr bool operator==(Q, Q) = default;
  friend constexpr std::strong_ordering operator<=>(Q, Q) = default;

 private:
  template <int, int>
  friend class Q;

  constexpr explicit Q(Raw raw) noexcept : raw_(raw) {}

  Raw raw_ = 0;
};

// Saturating same-format sum and difference. Bounds are checked before the sum is formed, so
// this works for 64-bit formats too.
template <int I, int F>
[[nodiscard]] constexpr Q<I, F> addSat(Q<I, F> a, Q<I, F> b) noexcept {
  using T = Q<I, F>;
  const std::int64_t x = a.raw();
  const std::int64_t y = b.raw();
  if (y > 0 && x > T::kRawMax - y) {
    return T::max();
  }
  if (y < 0 && x < T::kRawMin - y) {
    return T::min();
  }
  return T::fromRaw(static_cast<typename T::Raw>(x + y));
}

template <int I, int F>
[[nodiscard]] constexpr Q<I, F> subSat(Q<I, F> a, Q<I, F> b) noexcept {
  using T = Q<I, F>;
  const std::int64_t x = a.raw();
  const std::int64_t y = b.raw();
  if (y < 0 && x > T::kRawMax + y) {
    return T::max();
  }
  if (y > 0 && x < T::kRawMin + y) {
    return T::min();
  }
  return T::fromRaw(static_cast<typename T::Raw>(x - y));
}

// Converts between formats: fractional bits dropped with `round`, integer range saturated.
// Gaining fractional bits is exact (saturating only if the target has fewer integer bits).
template <QFormat To, int I, int F>
[[nodiscard]] constexpr To rescale(Q<I, F> x, Round round) noexcept {
  constexpr int kToFrac = To::kFracBits;
  const std::int64_t raw = x.raw();
  std::int64_t r = 0;
  if constexpr (kToFrac >= F) {
    constexpr int kShift = kToFrac - F;
    // Compare before shifting: raw << kShift is formed only when it lands in range.
    if (raw > (std::int64_t{To::kRawMax} >> kShift)) {
      return To::max();
    }
    if (raw < (std::int64_t{To::kRawMin} >> kShift)) {
      return To::min();
    }
    r = raw << kShift;
  } else {
    r = roundingShiftRight(raw, F - kToFrac, round);
    r = r < To::kRawMin ? To::kRawMin : (r > To::kRawMax ? To::kRawMax : r);
  }
  return To::fromRaw(static_cast<typename To::Raw>(r));
}

// The same with the rounding fixed at compile time: rescale<Q<1, 14>, Round::kHalfUp>(x).
template <QFormat To, Round kRound, int I, int F>
[[nodiscard]] constexpr To rescale(Q<I, F> x) noexcept {
  return rescale<To>(x, kRound);
}

}  // namespace smx::algo
