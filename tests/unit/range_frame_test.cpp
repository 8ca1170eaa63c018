// The host's reading of range frames from the network: a frame's header is checked against what
// the device announced before its depth is allocated.
#include "range_frame.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "alloc_counter.hpp"

namespace smx::host {
namespace {

using protocol::Compression;

// The 38 bytes of a range frame's fields (little-endian, docs/protocol.md) with no depth: what a
// hostile or broken device can send in place of a frame.
std::vector<std::byte> bareRangeFrame(std::uint8_t camera, std::uint16_t width,
                                      std::uint16_t height) {
  std::vector<std::byte> payload;
  const auto put = [&](std::uint64_t value, int bytes) {
    for (int i = 0; i < bytes; ++i) {
      payload.push_back(static_cast<std::byte>(value >> (8 * i)));
    }
  };
  put(camera, 1);
  put(static_cast<std::uint8_t>(Compression::kRvl), 1);
  put(width, 2);
  put(height, 2);
  put(7, 8);        // frame
  put(1000, 8);     // capture_ns
  put(2000, 8);     // queued_ns
  put(100'000, 4);  // depth_unit_nm
  put(0, 4);        // decode_us
  return payload;
}

constexpr AnnouncedFrames kTwoVga = {.cameras = 2, .width = 640, .height = 480};

// Given a 38-byte frame claiming 65535x65535 pixels (8.6 GB of depth) from a device that
// announced 640x480, when received, then it is refused naming both sizes, and nothing near the
// claim is allocated (a reader that sizes the depth from the header asks for 8.6 GB here).
TEST(RangeFrame, SizeOtherThanAnnouncedIsRefusedBeforeAllocating) {
  const auto payload = bareRangeFrame(0, 65535, 65535);
  const test::AllocationCounter counter;
  const auto frame = receiveRangeFrame(payload, kTwoVga, 0);
  EXPECT_LT(counter.bytes(), 4096U);
  ASSERT_FALSE(frame.has_value());
  EXPECT_NE(frame.error().find("65535x65535"), std::string::npos) << frame.error();
  EXPECT_NE(frame.error().find("640x480"), std::string::npos) << frame.error();

  // Smaller than announced is refused too: the host's outputs are sized from the announcement.
  const auto small = receiveRangeFrame(bareRangeFrame(0, 320, 240), kTwoVga, 0);
  ASSERT_FALSE(small.has_value());
  EXPECT_NE(small.error().find("320x240"), std::string::npos) << small.error();
}

// Given a device that announced 65535x65535 itself (its capabilities are network input too),
// when a frame of that size arrives, then it is refused as more than a range frame carries,
// before anything near its size is allocated.
TEST(RangeFrame, AnnouncedSizeBeyondWhatAFrameCarriesIsRefused) {
  const auto payload = bareRangeFrame(0, 65535, 65535);
  const test::AllocationCounter counter;
  const auto frame = receiveRangeFrame(payload, {.cameras = 1, .width = 65535, .height = 65535}, 0);
  EXPECT_LT(counter.bytes(), 4096U);
  ASSERT_FALSE(frame.has_value());
  EXPECT_NE(frame.error().find("65535x65535"), std::string::npos) << frame.error();
  EXPECT_NE(frame.error().find("2097152 pixels"), std::string::npos) << frame.error();
}

// Given a device that announced 2 cameras, when a frame names camera 2, then it is refused
// naming the index and the count.
TEST(RangeFrame, CameraIndexBeyondTheAnnouncedCountIsRefused) {
  const auto frame = receiveRangeFrame(bareRangeFrame(2, 640, 480), kTwoVga, 0);
  ASSERT_FALSE(frame.has_value());
  EXPECT_NE(frame.error().find("camera 2"), std::string::npos) << frame.error();
  EXPECT_NE(frame.error().find("2 camera"), std::string::npos) << frame.error();
}

// Given a frame of the announced size encoded as the device encodes it, when received, then its
// header and depth come back as sent, with the message's size and the receive time.
TEST(RangeFrame, AnnouncedFrameDecodesAsSent) {
  constexpr int kW = 5;
  constexpr int kH = 3;
  std::vector<std::uint16_t> depth(kW * kH);
  for (std::size_t i = 0; i < depth.size(); ++i) {
    depth[i] = static_cast<std::uint16_t>(i % 4 == 0 ? 0 : 9000 + i);
  }
  std::vector<std::byte> buffer(protocol::rangeFrameBound(kW, kH));
  const auto message =
      protocol::encodeRangeFrame({.camera = 1, .compression = Compression::kRvl, .frame = 42},
                                 *algo::ConstDepthPlane::packed(depth, kW, kH), buffer);
  ASSERT_TRUE(message.has_value());
  const auto frame = receiveRangeFrame(message->subspan(protocol::kHeaderBytes),
                                       {.cameras = 2, .width = kW, .height = kH}, 123);
  ASSERT_TRUE(frame.has_value()) << frame.error();
  EXPECT_EQ(frame->header.camera, 1);
  EXPECT_EQ(frame->header.frame, 42U);
  EXPECT_EQ(frame->depth, depth);
  EXPECT_EQ(frame->wireBytes, message->size());
  EXPECT_EQ(frame->receivedNs, 123);
}

// The same with its confidence plane: depth and confidence of a 5x3 image, holes every fourth
// pixel in both, as the device encodes them.
struct ConfidenceFrame {
  std::vector<std::uint16_t> depth;
  std::vector<std::uint8_t> confidence;
  std::vector<std::byte> payload;
};

ConfidenceFrame confidenceFrame(Compression compression) {
  constexpr int kW = 5;
  constexpr int kH = 3;
  ConfidenceFrame f;
  for (int i = 0; i < kW * kH; ++i) {
    f.depth.push_back(static_cast<std::uint16_t>(i % 4 == 0 ? 0 : 9000 + i));
    f.confidence.push_back(static_cast<std::uint8_t>(i % 4 == 0 ? 0 : 200 + i));
  }
  std::vector<std::byte> buffer(protocol::rangeFrameBound(kW, kH, true));
  const auto message = protocol::encodeRangeFrame(
      {.camera = 0, .compression = compression, .frame = 3},
      *algo::ConstDepthPlane::packed(f.depth, kW, kH),
      *algo::ImageView<const std::uint8_t>::packed(f.confidence, kW, kH), buffer);
  EXPECT_TRUE(message.has_value());
  f.payload.assign(message->begin() + protocol::kHeaderBytes, message->end());
  return f;
}

constexpr AnnouncedFrames kTiny = {.cameras = 1, .width = 5, .height = 3};
constexpr auto kWithConfidence = protocol::MessageType::kRangeFrameConfidence;

TEST(RangeFrame, ConfidenceFrameDecodesAsSent) {
  for (const Compression compression : {Compression::kRvl, Compression::kNone}) {
    const ConfidenceFrame sent = confidenceFrame(compression);
    const auto frame = receiveRangeFrame(sent.payload, kTiny, 0, kWithConfidence);
    ASSERT_TRUE(frame.has_value()) << frame.error();
    EXPECT_EQ(frame->depth, sent.depth);
    EXPECT_EQ(frame->confidence, sent.confidence);
  }
  // A plain range frame carries no confidence.
  std::vector<std::uint16_t> depth(15, 1000);
  std::vector<std::byte> buffer(protocol::rangeFrameBound(5, 3));
  const auto plain =
      protocol::encodeRangeFrame({}, *algo::ConstDepthPlane::packed(depth, 5, 3), buffer);
  ASSERT_TRUE(plain.has_value());
  const auto frame = receiveRangeFrame(plain->subspan(protocol::kHeaderBytes), kTiny, 0);
  ASSERT_TRUE(frame.has_value()) << frame.error();
  EXPECT_TRUE(frame->confidence.empty());
}

// Given confidence planes one byte short, raw or RVL, when received, then the frame is refused
// naming the confidence plane.
TEST(RangeFrame, ConfidencePlaneOfTheWrongSizeIsRefusedNamingIt) {
  for (const Compression compression : {Compression::kRvl, Compression::kNone}) {
    ConfidenceFrame sent = confidenceFrame(compression);
    sent.payload.pop_back();
    const auto frame = receiveRangeFrame(sent.payload, kTiny, 0, kWithConfidence);
    ASSERT_FALSE(frame.has_value());
    EXPECT_NE(frame.error().find("confidence plane"), std::string::npos) << frame.error();
  }
}

// Given a confidence frame claiming a depth of 4 GB and one claiming 65535x65535 pixels from a
// device that announced that size, when received, then both are refused before anything near
// the claims is allocated: the depth's size prefix is checked against the payload, and a frame
// with confidence carries at most a third of the payload limit in pixels.
TEST(RangeFrame, HostileConfidenceFrameSizesAreRefusedBeforeAllocating) {
  std::vector<std::byte> hugeDepth = bareRangeFrame(0, 5, 3);
  for (int i = 0; i < 4; ++i) {
    hugeDepth.push_back(std::byte{0xFF});
  }
  std::vector<std::byte> huge = bareRangeFrame(0, 65535, 65535);
  huge.resize(huge.size() + 4, std::byte{0});  // depth size 0, no confidence
  const test::AllocationCounter counter;
  const auto depthFrame = receiveRangeFrame(hugeDepth, kTiny, 0, kWithConfidence);
  const auto hugeFrame =
      receiveRangeFrame(huge, {.cameras = 1, .width = 65535, .height = 65535}, 0, kWithConfidence);
  EXPECT_LT(counter.bytes(), 4096U);
  ASSERT_FALSE(depthFrame.has_value());
  EXPECT_NE(depthFrame.error().find("depth size"), std::string::npos) << depthFrame.error();
  ASSERT_FALSE(hugeFrame.has_value());
  EXPECT_NE(hugeFrame.error().find("1398101 pixels"), std::string::npos) << hugeFrame.error();
}

}  // namespace
}  // namespace smx::host
