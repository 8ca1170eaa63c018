#include "smx/linux/pixel_convert.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "yuv_reference.hpp"

namespace smx::lnx {
namespace {

using algo::Rgb8;
using algo::RgbView;

constexpr std::byte kPad{0xA5};

// An RGB destination with `padPixels` extra pixels per row, all set to a marker, so a converter
// that writes past a row is caught.
struct Destination {
  Destination(int width, int height, int padPixels)
      : stridePixels(width + padPixels),
        pixels(static_cast<std::size_t>(stridePixels) * static_cast<std::size_t>(height),
               Rgb8{1, 2, 3}),
        view(*RgbView::create(reinterpret_cast<std::byte*>(pixels.data()), width, height,
                              std::ptrdiff_t{3} * stridePixels)) {}
  int stridePixels;
  std::vector<Rgb8> pixels;
  RgbView view;
};

int maxChannelError(Rgb8 got, int r, int g, int b) {
  return std::max({std::abs(got.r - r), std::abs(got.g - g), std::abs(got.b - b)});
}

TEST(PixelConvertYuyv, NominalBlackWhiteAndGreyAreExact) {
  // Given the nominal range ends and mid grey, Then they map to the RGB range ends exactly.
  EXPECT_EQ(yuvToRgb(16, 128, 128), (Rgb8{0, 0, 0}));
  EXPECT_EQ(yuvToRgb(235, 128, 128), (Rgb8{255, 255, 255}));
  EXPECT_EQ(yuvToRgb(126, 128, 128), (Rgb8{128, 128, 128}));  // 110 * 255/219 = 128.08
  // Out of the nominal range clips instead of wrapping.
  EXPECT_EQ(yuvToRgb(0, 128, 128), (Rgb8{0, 0, 0}));
  EXPECT_EQ(yuvToRgb(255, 128, 128), (Rgb8{255, 255, 255}));
  EXPECT_EQ(yuvToRgb(255, 255, 255).r, 255);
  EXPECT_EQ(yuvToRgb(0, 0, 0).r, 0);
}

TEST(PixelConvertYuyv, EveryInputIsWithinOneOfTheDoubleReference) {
  // Given every (Y, U, V): for each U, an image of 256 rows (V) by 256 pixels (Y), where each
  // YUYV pair shares the row's U and V.
  constexpr int kSide = 256;
  std::vector<std::byte> src(static_cast<std::size_t>(kSide) * kSide * 2);
  const Destination dst(kSide, kSide, 0);
  int worst = 0;
  long long inexact = 0;
  for (int u = 0; u < 256; ++u) {
    for (int v = 0; v < kSide; ++v) {
      for (int x = 0; x < kSide; x += 2) {
        std::byte* p =
            &src[2 * (static_cast<std::size_t>(v) * kSide + static_cast<std::size_t>(x))];
        p[0] = static_cast<std::byte>(x);
        p[1] = static_cast<std::byte>(u);
        p[2] = static_cast<std::byte>(x + 1);
        p[3] = static_cast<std::byte>(v);
      }
    }
    // When converted
    ASSERT_TRUE(convertYuyvToRgb(src, std::ptrdiff_t{2} * kSide, dst.view));
    // Then each channel is within 1 of the exact value rounded to nearest.
    for (int v = 0; v < kSide; ++v) {
      for (int y = 0; y < kSide; ++y) {
        const test::RgbDouble want = test::yuvToRgbExact(y, u, v);
        const int error = maxChannelError(dst.view(y, v), test::roundClamp8(want.r),
                                          test::roundClamp8(want.g), test::roundClamp8(want.b));
        if (error > 0) {
          ++inexact;
        }
        ASSERT_LE(error, 1) << "Y=" << y << " U=" << u << " V=" << v;
        worst = std::max(worst, error);
      }
    }
  }
  EXPECT_LE(worst, 1);
  // Rounding, not truncation: off by one only where the exact value is within ~0.005 of a tie
  // (measured: 8639 of 2^24 inputs, 0.05%; truncating would be about half of them).
  EXPECT_LT(inexact, 256LL * 256 * 256 / 1000) << "too many results off by one";
}

struct StrideCase {
  int width;
  int height;
  int srcPadBytes;
  int dstPadPixels;
};

class PixelConvertStride : public testing::TestWithParam<StrideCase> {};

TEST_P(PixelConvertStride, YuyvHonoursBothStridesAndMatchesTheReference) {
  const StrideCase c = GetParam();
  // Given random YUYV rows with padding bytes that must not be read as pixels
  const std::ptrdiff_t stride = std::ptrdiff_t{2} * c.width + c.srcPadBytes;
  std::vector<std::byte> src(static_cast<std::size_t>(stride * c.height), kPad);
  std::mt19937 rng(1234U + static_cast<unsigned>(c.width * 31 + c.height));
  std::uniform_int_distribution<int> byte(0, 255);
  for (int y = 0; y < c.height; ++y) {
    for (int i = 0; i < 2 * c.width; ++i) {
      src[static_cast<std::size_t>(y * stride + i)] = static_cast<std::byte>(byte(rng));
    }
  }
  const Destination dst(c.width, c.height, c.dstPadPixels);
  // When converted
  ASSERT_TRUE(convertYuyvToRgb(src, stride, dst.view));
  // Then every pixel matches the reference of its pair's U and V
  for (int y = 0; y < c.height; ++y) {
    for (int x = 0; x < c.width; ++x) {
      const auto at = [&](int i) {
        return std::to_integer<int>(src[static_cast<std::size_t>(y * stride + i)]);
      };
      const int pair = (x / 2) * 4;
      const test::RgbDouble want =
          test::yuvToRgbExact(at(pair + (x % 2) * 2), at(pair + 1), at(pair + 3));
      EXPECT_LE(maxChannelError(dst.view(x, y), test::roundClamp8(want.r),
                                test::roundClamp8(want.g), test::roundClamp8(want.b)),
                1)
          << x << "," << y;
    }
    // And the destination's row padding is untouched.
    for (int x = c.width; x < dst.stridePixels; ++x) {
      EXPECT_EQ(dst.pixels[static_cast<std::size_t>(y * dst.stridePixels + x)], (Rgb8{1, 2, 3}));
    }
  }
}

TEST_P(PixelConvertStride, Bgr24SwapsEveryPixelAndHonoursBothStrides) {
  const StrideCase c = GetParam();
  // Given random BGR rows with padding
  const std::ptrdiff_t stride = std::ptrdiff_t{3} * c.width + c.srcPadBytes;
  std::vector<std::byte> src(static_cast<std::size_t>(stride * c.height), kPad);
  std::mt19937 rng(99U + static_cast<unsigned>(c.width * 7 + c.height));
  std::uniform_int_distribution<int> byte(0, 255);
  for (int y = 0; y < c.height; ++y) {
    for (int i = 0; i < 3 * c.width; ++i) {
      src[static_cast<std::size_t>(y * stride + i)] = static_cast<std::byte>(byte(rng));
    }
  }
  const Destination dst(c.width, c.height, c.dstPadPixels);
  // When converted
  ASSERT_TRUE(convertBgr24ToRgb(src, stride, dst.view));
  // Then r, g, b are the source's bytes 2, 1, 0 of each pixel
  for (int y = 0; y < c.height; ++y) {
    for (int x = 0; x < c.width; ++x) {
      const auto at = [&](int i) {
        return std::to_integer<std::uint8_t>(
            src[static_cast<std::size_t>(y * stride + 3 * std::ptrdiff_t{x} + i)]);
      };
      EXPECT_EQ(dst.view(x, y), (Rgb8{at(2), at(1), at(0)})) << x << "," << y;
    }
    for (int x = c.width; x < dst.stridePixels; ++x) {
      EXPECT_EQ(dst.pixels[static_cast<std::size_t>(y * dst.stridePixels + x)], (Rgb8{1, 2, 3}));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, PixelConvertStride,
                         testing::Values(StrideCase{2, 1, 0, 0}, StrideCase{2, 3, 1, 1},
                                         StrideCase{6, 5, 3, 0}, StrideCase{18, 7, 7, 2},
                                         StrideCase{64, 9, 0, 3}, StrideCase{66, 17, 61, 0},
                                         StrideCase{642, 3, 5, 1}),
                         [](const testing::TestParamInfo<StrideCase>& param) {
                           const StrideCase& c = param.param;
                           return std::to_string(c.width) + "x" + std::to_string(c.height) +
                                  "_srcpad" + std::to_string(c.srcPadBytes) + "_dstpad" +
                                  std::to_string(c.dstPadPixels);
                         });

TEST(PixelConvertBgr24, OnePixelAndOddSizes) {
  // Given 1x1 and an odd-sized image packed tightly
  for (const auto& [w, h] : {std::pair{1, 1}, std::pair{3, 5}, std::pair{7, 1}}) {
    std::vector<std::byte> src(static_cast<std::size_t>(3 * w * h));
    for (std::size_t i = 0; i < src.size(); ++i) {
      src[i] = static_cast<std::byte>(static_cast<unsigned char>(i * 37 + 11));
    }
    const Destination dst(w, h, 0);
    ASSERT_TRUE(convertBgr24ToRgb(src, std::ptrdiff_t{3} * w, dst.view));
    EXPECT_EQ(dst.view(0, 0), (Rgb8{static_cast<std::uint8_t>(2 * 37 + 11),
                                    static_cast<std::uint8_t>(1 * 37 + 11), 11}));
    const std::size_t last = src.size() - 3;
    EXPECT_EQ(dst.view(w - 1, h - 1), (Rgb8{std::to_integer<std::uint8_t>(src[last + 2]),
                                            std::to_integer<std::uint8_t>(src[last + 1]),
                                            std::to_integer<std::uint8_t>(src[last])}));
  }
}

TEST(PixelConvertYuyv, RejectsOddWidthsShortSourcesAndSmallStrides) {
  std::vector<std::byte> src(1024);
  const Destination odd(3, 2, 0);
  const Destination one(1, 1, 0);
  const Destination even(4, 2, 0);
  // Odd widths (1x1 included): half a YUYV pair does not exist.
  EXPECT_EQ(convertYuyvToRgb(src, 8, odd.view).error().code, hal::HalErrc::kInvalidArgument);
  EXPECT_EQ(convertYuyvToRgb(src, 8, one.view).error().code, hal::HalErrc::kInvalidArgument);
  // A stride smaller than a row.
  EXPECT_EQ(convertYuyvToRgb(src, 7, even.view).error().code, hal::HalErrc::kInvalidArgument);
  // A source one byte short of the last row (the last row needs no padding).
  EXPECT_EQ(convertYuyvToRgb(std::span(src).first(10 + 7), 10, even.view).error().code,
            hal::HalErrc::kInvalidArgument);
  EXPECT_TRUE(convertYuyvToRgb(std::span(src).first(10 + 8), 10, even.view));
  // An empty image needs no source.
  const Destination empty(0, 0, 0);
  EXPECT_TRUE(convertYuyvToRgb({}, 0, empty.view));
}

TEST(PixelConvertBgr24, RejectsShortSourcesAndSmallStrides) {
  std::vector<std::byte> src(64);
  const Destination dst(3, 2, 0);
  EXPECT_EQ(convertBgr24ToRgb(src, 8, dst.view).error().code, hal::HalErrc::kInvalidArgument);
  EXPECT_EQ(convertBgr24ToRgb(std::span(src).first(11 + 8), 11, dst.view).error().code,
            hal::HalErrc::kInvalidArgument);
  EXPECT_TRUE(convertBgr24ToRgb(std::span(src).first(11 + 9), 11, dst.view));
}

}  // namespace
}  // namespace smx::lnx
