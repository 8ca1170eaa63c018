#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "smx/algo/image_view.hpp"
#include "smx/algo/rounding.hpp"
#include "smx/hal/error.hpp"

// Wire formats a V4L2 camera delivers, converted into the 8-bit RGB frames the pipeline takes.
// Integer only (this runs per frame on the board). The destination's size is the frame size;
// the source is `srcStrideBytes` per row (V4L2 bytesperline, padding allowed) and must hold
// every row: srcStrideBytes * (height - 1) + one row.
//
// @par YUYV numerics (ITU-R BT.601, limited range: Y 16..235, Cb/Cr 16..240)
//   R = 255/219 (Y-16)                       + 2(1-Kr) 255/224 (Cr-128)
//   G = 255/219 (Y-16) - 2(1-Kb)Kb/Kg 255/224 (Cb-128) - 2(1-Kr)Kr/Kg 255/224 (Cr-128)
//   B = 255/219 (Y-16) + 2(1-Kb) 255/224 (Cb-128)
//   with Kr = 0.299, Kb = 0.114, Kg = 1 - Kr - Kb. Coefficients are Q2.16 (round to nearest at
//   compile time); products and the sum are int32 (|sum| < 2^26, no overflow); the sum is
//   rounded half-up to an integer and saturated to 0..255 (values outside the nominal range,
//   e.g. Y < 16, clip instead of wrapping). Max error against the exact real result rounded to
//   nearest is 1 (the coefficient error is < 2^-17 * 3 * 255 < 0.006), measured in the tests.
namespace smx::lnx {

namespace detail {

inline constexpr int kYuvFracBits = 16;

// A coefficient in Q2.16 (an int32 in [-2^18, 2^18)): the largest (B from Cb) is 2.02.
consteval std::int32_t yuvCoefficient(double value) {
  constexpr std::int64_t kLimit = std::int64_t{1} << (2 + kYuvFracBits);
  return static_cast<std::int32_t>(
      algo::detail::roundDouble(value * static_cast<double>(std::int64_t{1} << kYuvFracBits),
                                algo::Round::kHalfEven, -kLimit, kLimit - 1));
}

inline constexpr double kKr = 0.299;
inline constexpr double kKb = 0.114;
inline constexpr double kKg = 1.0 - kKr - kKb;
inline constexpr double kYScale = 255.0 / 219.0;
inline constexpr double kCScale = 255.0 / 224.0;

inline constexpr std::int32_t kY = yuvCoefficient(kYScale);
inline constexpr std::int32_t kRv = yuvCoefficient(2.0 * (1.0 - kKr) * kCScale);
inline constexpr std::int32_t kGu = yuvCoefficient(2.0 * (1.0 - kKb) * kKb / kKg * kCScale);
inline constexpr std::int32_t kGv = yuvCoefficient(2.0 * (1.0 - kKr) * kKr / kKg * kCScale);
inline constexpr std::int32_t kBu = yuvCoefficient(2.0 * (1.0 - kKb) * kCScale);

[[nodiscard]] constexpr std::uint8_t yuvChannel(std::int32_t sum) {
  return algo::saturateCast<std::uint8_t>(
      algo::roundingShiftRight(sum, kYuvFracBits, algo::Round::kHalfUp));
}

}  // namespace detail

// One pixel; the image converter below is built on it.
[[nodiscard]] constexpr algo::Rgb8 yuvToRgb(std::uint8_t y, std::uint8_t u, std::uint8_t v) {
  const std::int32_t yTerm = detail::kY * (std::int32_t{y} - 16);
  const std::int32_t uc = std::int32_t{u} - 128;
  const std::int32_t vc = std::int32_t{v} - 128;
  return {.r = detail::yuvChannel(yTerm + detail::kRv * vc),
          .g = detail::yuvChannel(yTerm - detail::kGu * uc - detail::kGv * vc),
          .b = detail::yuvChannel(yTerm + detail::kBu * uc)};
}

// YUYV 4:2:2 (Y0 U Y1 V per two pixels, V4L2_PIX_FMT_YUYV). The width must be even
// (kInvalidArgument otherwise, as for a short source or a stride smaller than a row).
[[nodiscard]] hal::HalResult<void> convertYuyvToRgb(std::span<const std::byte> src,
                                                    std::ptrdiff_t srcStrideBytes,
                                                    const algo::RgbView& dst);

// BGR24 (b, g, r per pixel, V4L2_PIX_FMT_BGR24): a byte swap per pixel.
[[nodiscard]] hal::HalResult<void> convertBgr24ToRgb(std::span<const std::byte> src,
                                                     std::ptrdiff_t srcStrideBytes,
                                                     const algo::RgbView& dst);

// Bytes a source needs for `height` rows of `rowBytes` at `strideBytes` (0 when height is 0).
[[nodiscard]] constexpr std::size_t sourceBytesNeeded(std::ptrdiff_t strideBytes,
                                                      std::ptrdiff_t rowBytes, int height) {
  return height <= 0 ? 0 : static_cast<std::size_t>(strideBytes * (height - 1) + rowBytes);
}

}  // namespace smx::lnx
