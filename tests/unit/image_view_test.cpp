#include "smx/algo/image_view.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <vector>

namespace smx::algo {
namespace {

// Given a V4L2-like RGB24 buffer whose bytesperline is padded to a size that is not a multiple
// of 3, when pixels are read through the view, then every row starts at y * stride bytes.
TEST(ImageView, RgbRowsFollowPaddedByteStride) {
  constexpr int kWidth = 5;
  constexpr int kHeight = 3;
  constexpr std::ptrdiff_t kStride = 17;  // 15 bytes of pixels + 2 padding
  std::vector<std::byte> buffer(kStride * kHeight, std::byte{0xEE});
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      auto* p = reinterpret_cast<std::uint8_t*>(buffer.data()) + y * kStride + x * 3;
      p[0] = static_cast<std::uint8_t>(10 * y + x);
      p[1] = 100;
      p[2] = 200;
    }
  }
  auto view = RgbView::create(buffer.data(), kWidth, kHeight, kStride);
  ASSERT_TRUE(view.has_value());
  EXPECT_EQ((*view)(4, 2), (Rgb8{24, 100, 200}));
  EXPECT_EQ(view->row(1).size(), 5U);
  EXPECT_EQ(view->row(1)[0].r, 10);
  ConstRgbView readOnly = *view;  // mutable converts to const
  EXPECT_EQ(readOnly(3, 1).r, 13);
}

TEST(ImageView, PlanesS16AndS32) {
  std::vector<std::int16_t> s16(6 * 4);
  auto p16 = PlaneS16::packed(s16, 6, 4);
  ASSERT_TRUE(p16.has_value());
  (*p16)(5, 3) = -32768;
  EXPECT_EQ(s16.back(), -32768);
  EXPECT_EQ(p16->strideBytes(), 12);

  std::vector<std::int32_t> s32(3 * 2);
  auto p32 = PlaneS32::packed(s32, 3, 2);
  ASSERT_TRUE(p32.has_value());
  (*p32)(0, 1) = 1 << 30;
  EXPECT_EQ(s32[3], 1 << 30);
}

TEST(ImageView, SubViewSharesMemoryAndClips) {
  std::vector<std::int32_t> pixels(8 * 6);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    pixels[i] = static_cast<std::int32_t>(i);
  }
  const auto full = *ConstPlaneS32::packed(pixels, 8, 6);
  const auto roi = full.sub(2, 1, 3, 2);
  EXPECT_EQ(roi.width(), 3);
  EXPECT_EQ(roi.height(), 2);
  EXPECT_EQ(roi(0, 0), 1 * 8 + 2);
  EXPECT_EQ(roi(2, 1), 2 * 8 + 4);
  const auto clipped = full.sub(6, 4, 10, 10);
  EXPECT_EQ(clipped.width(), 2);
  EXPECT_EQ(clipped.height(), 2);
  EXPECT_EQ(clipped(1, 1), 5 * 8 + 7);
  EXPECT_TRUE(full.sub(9, 0, 2, 2).empty());
}

TEST(ImageView, CreateRejectsBadGeometry) {
  std::array<std::byte, 64> buffer{};
  EXPECT_EQ(PlaneS16::create(buffer.data(), 8, 2, 10).error().code, Errc::kSizeMismatch);
  EXPECT_EQ(PlaneS16::create(buffer.data(), 2, 2, 5).error().code, Errc::kInvalidArgument);
  EXPECT_EQ(PlaneS32::create(buffer.data() + 1, 2, 2, 8).error().code, Errc::kInvalidArgument);
  EXPECT_EQ(PlaneS16::create(buffer.data(), -1, 2, 8).error().code, Errc::kInvalidArgument);
  EXPECT_EQ(PlaneS16::create(nullptr, 2, 2, 8).error().code, Errc::kInvalidArgument);
  std::vector<std::int16_t> tooSmall(5);
  EXPECT_EQ(PlaneS16::packed(tooSmall, 3, 2).error().code, Errc::kSizeMismatch);
}

}  // namespace
}  // namespace smx::algo
