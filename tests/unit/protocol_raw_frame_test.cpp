// capture-raw and raw-frame (docs/protocol.md, "Raw capture"): the documented byte layout, frames
// split into bands and put back together, and hostile sizes refused before anything is copied.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <random>
#include <span>
#include <vector>

#include "alloc_counter.hpp"
#include "smx/protocol/messages.hpp"
#include "smx/protocol/stream_parser.hpp"

namespace smx::protocol {
namespace {

using Bytes = std::vector<std::byte>;

std::vector<algo::Rgb8> randomImage(int width, int height, unsigned seed) {
  std::mt19937 random(seed);
  std::vector<algo::Rgb8> pixels(static_cast<std::size_t>(width) *
                                 static_cast<std::size_t>(height));
  for (auto& p : pixels) {
    p = {static_cast<std::uint8_t>(random()), static_cast<std::uint8_t>(random()),
         static_cast<std::uint8_t>(random())};
  }
  return pixels;
}

std::uint64_t readLe(std::span<const std::byte> bytes, std::size_t at, std::size_t size) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < size; ++i) {
    value |= std::to_integer<std::uint64_t>(bytes[at + i]) << (8 * i);
  }
  return value;
}

TEST(CaptureRaw, IsTheProjectorMaskAsFourBytes) {
  Bytes buffer(64);
  const auto message = encode(CaptureRaw{0b101U}, buffer);
  ASSERT_TRUE(message.has_value());
  ASSERT_EQ(message->size(), kHeaderBytes + 4);
  EXPECT_EQ(std::to_integer<int>((*message)[5]), 10);  // the type byte
  EXPECT_EQ(readLe(*message, kHeaderBytes, 4), 0b101U);
  const auto back = decodeCaptureRaw(message->subspan(kHeaderBytes));
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->projectorsMask, 0b101U);

  const std::array<std::byte, 3> shorter{};
  EXPECT_FALSE(decodeCaptureRaw(shorter).has_value());
  const std::array<std::byte, 5> longer{};
  EXPECT_FALSE(decodeCaptureRaw(longer).has_value());
}

// Given a 3×2 image, when its second row is sent as a band, then the bytes are the documented
// fields at their offsets, followed by that row's r g b bytes.
TEST(RawFrame, BandBytesAreTheDocumentedLayout) {
  const auto pixels = randomImage(3, 2, 1);
  const auto image = *algo::ConstRgbView::packed(pixels, 3, 2);
  Bytes buffer(256);
  const RawFrameHeader header{.camera = 1,
                              .projectorsMask = 2,
                              .firstRow = 1,
                              .rows = 1,
                              .capture = 0x0102030405060708ULL,
                              .captureTimestampNs = 99};
  const auto message = encodeRawFrame(header, image, buffer);
  ASSERT_TRUE(message.has_value());
  const std::span<const std::byte> payload = message->subspan(kHeaderBytes);
  ASSERT_EQ(payload.size(), 29U + 9U);
  EXPECT_EQ(std::to_integer<int>((*message)[5]), 11);
  EXPECT_EQ(readLe(payload, 0, 1), 1U);   // camera
  EXPECT_EQ(readLe(payload, 1, 4), 2U);   // projectors
  EXPECT_EQ(readLe(payload, 5, 2), 3U);   // width
  EXPECT_EQ(readLe(payload, 7, 2), 2U);   // height
  EXPECT_EQ(readLe(payload, 9, 2), 1U);   // first_row
  EXPECT_EQ(readLe(payload, 11, 2), 1U);  // rows
  EXPECT_EQ(readLe(payload, 13, 8), 0x0102030405060708ULL);
  EXPECT_EQ(readLe(payload, 21, 8), 99U);  // capture_ns
  for (std::size_t x = 0; x < 3; ++x) {
    const algo::Rgb8 p = pixels[3 + x];
    EXPECT_EQ(readLe(payload, 29 + 3 * x, 1), p.r);
    EXPECT_EQ(readLe(payload, 29 + 3 * x + 1, 1), p.g);
    EXPECT_EQ(readLe(payload, 29 + 3 * x + 2, 1), p.b);
  }
}

// Given frames from 1×1 to the widest a header can describe, when every band is encoded, sent
// through the parser and decoded, then the bands tile the frame exactly and add up to
// rawFrameBound().
TEST(RawFrame, BandsTileTheFrameAndFitTheBound) {
  for (const auto& [width, height] : {std::pair{1, 1}, std::pair{7, 5}, std::pair{640, 480},
                                      std::pair{1000, 701}, std::pair{65535, 7}}) {
    SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height));
    const auto pixels = randomImage(width, height, static_cast<unsigned>(width));
    const auto image = *algo::ConstRgbView::packed(pixels, width, height);
    const int band = rawFrameBandRows(width);
    ASSERT_GE(band, 1);
    ASSERT_LE(3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(band),
              kRawBandPixelBytes);

    Bytes stream(rawFrameBound(width, height));
    std::size_t used = 0;
    for (int row = 0; row < height; row += band) {
      const RawFrameHeader header{.camera = 0,
                                  .firstRow = static_cast<std::uint16_t>(row),
                                  .rows = static_cast<std::uint16_t>(std::min(band, height - row))};
      const auto message = encodeRawFrame(header, image, std::span(stream).subspan(used));
      ASSERT_TRUE(message.has_value()) << message.error().message;
      used += message->size();
    }
    EXPECT_EQ(used, stream.size());

    StreamParser parser(kRawBandPixelBytes + 1024);
    std::vector<algo::Rgb8> back(pixels.size());
    std::vector<int> covered(static_cast<std::size_t>(height), 0);
    for (std::size_t at = 0; at < used;) {
      at += parser.feed(std::span(stream).subspan(at, used - at));
      for (auto next = parser.next(); next && next->has_value(); next = parser.next()) {
        ASSERT_EQ((*next)->type, MessageType::kRawFrame);
        const auto frame = decodeRawFrame((*next)->payload);
        ASSERT_TRUE(frame.has_value()) << frame.error().message;
        ASSERT_EQ(frame->header.width, width);
        ASSERT_EQ(frame->header.height, height);
        std::memcpy(back.data() + std::size_t{frame->header.firstRow} * frame->header.width,
                    frame->pixels.data(), frame->pixels.size());
        for (int r = 0; r < frame->header.rows; ++r) {
          ++covered[static_cast<std::size_t>(frame->header.firstRow + r)];
        }
      }
    }
    EXPECT_EQ(back, pixels);
    EXPECT_EQ(std::count(covered.begin(), covered.end(), 1), height);
  }
}

// A band the header places outside its frame, or whose pixels do not match it, is refused.
TEST(RawFrame, HostileBandsAreRefusedNamingTheProblem) {
  const auto pixels = randomImage(4, 4, 2);
  const auto image = *algo::ConstRgbView::packed(pixels, 4, 4);
  Bytes buffer(256);
  const auto good = encodeRawFrame(RawFrameHeader{.firstRow = 2, .rows = 2}, image, buffer);
  ASSERT_TRUE(good.has_value());
  const Bytes payload(good->begin() + kHeaderBytes, good->end());
  ASSERT_TRUE(decodeRawFrame(payload).has_value());

  const auto refused = [&](std::size_t offset, std::uint16_t value, const char* needle) {
    Bytes bad = payload;
    bad[offset] = static_cast<std::byte>(value & 0xFFU);
    bad[offset + 1] = static_cast<std::byte>(value >> 8U);
    const auto frame = decodeRawFrame(bad);
    ASSERT_FALSE(frame.has_value()) << needle;
    EXPECT_NE(std::string(frame.error().message).find(needle), std::string::npos)
        << frame.error().message;
  };
  refused(5, 0, "zero size");                // width 0
  refused(7, 3, "past the frame's height");  // height 3 < first_row 2 + rows 2
  refused(9, 3, "past the frame's height");  // first_row 3 + rows 2 > 4
  refused(11, 0, "zero rows");               // rows 0
  refused(11, 1, "rows x width x 3");        // rows 1 with two rows of pixels
  refused(5, 0xFFFF, "rows x width x 3");    // a huge width claims more pixels than sent

  EXPECT_FALSE(decodeRawFrame(std::span(payload).first(28)).has_value());
  Bytes padded = payload;
  padded.push_back(std::byte{0});
  EXPECT_FALSE(decodeRawFrame(padded).has_value());

  EXPECT_FALSE(encodeRawFrame(RawFrameHeader{.firstRow = 3, .rows = 2}, image, buffer));
  EXPECT_FALSE(encodeRawFrame(RawFrameHeader{.rows = 0}, image, buffer));
  Bytes tiny(40);
  EXPECT_EQ(encodeRawFrame(RawFrameHeader{.rows = 4}, image, tiny).error().code,
            ProtocolErrc::kBufferTooSmall);
}

TEST(RawFrame, EncodingAndDecodingABandNeverAllocates) {
  const auto pixels = randomImage(64, 48, 3);
  const auto image = *algo::ConstRgbView::packed(pixels, 64, 48);
  Bytes buffer(rawFrameBound(64, 48));
  const test::AllocationCounter allocations;
  const auto message = encodeRawFrame(RawFrameHeader{.rows = 48}, image, buffer);
  const auto frame = decodeRawFrame(message->subspan(kHeaderBytes));
  EXPECT_EQ(allocations.allocations(), 0U);
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->pixels.size(), pixels.size() * 3);
}

}  // namespace
}  // namespace smx::protocol
