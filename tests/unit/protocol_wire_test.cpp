#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <span>
#include <string_view>
#include <vector>

#include "alloc_counter.hpp"
#include "smx/protocol/crc32.hpp"
#include "smx/protocol/messages.hpp"
#include "smx/protocol/rvl.hpp"
#include "smx/protocol/stream_parser.hpp"

namespace smx::protocol {
namespace {

using Bytes = std::vector<std::byte>;

Bytes copy(std::span<const std::byte> bytes) {
  return {bytes.begin(), bytes.end()};
}

// CRC-32 bit by bit from its definition (reflected polynomial 0xEDB88320, initial and final
// inversion): an independent reference for the table-driven one.
std::uint32_t referenceCrc32(std::span<const std::byte> bytes) {
  std::uint32_t crc = 0xFFFFFFFFU;
  for (const std::byte b : bytes) {
    crc ^= std::to_integer<std::uint32_t>(b);
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc >> 1) ^ (0xEDB88320U & (0U - (crc & 1U)));
    }
  }
  return ~crc;
}

Bytes encoded(const auto& message) {
  Bytes buffer(1 << 16);
  auto result = encode(message, buffer);
  EXPECT_TRUE(result.has_value());
  return result ? copy(*result) : Bytes{};
}

std::vector<Message> parseAll(StreamParser& parser, std::vector<ProtocolErrc>* errors = nullptr) {
  std::vector<Message> out;
  while (true) {
    auto next = parser.next();
    if (!next) {
      if (errors != nullptr) {
        errors->push_back(next.error().code);
      }
      continue;
    }
    if (!next->has_value()) {
      return out;
    }
    out.push_back(**next);
  }
}

TEST(Crc32, MatchesTheStandardCheckValueAndTheBitwiseDefinition) {
  constexpr std::string_view kCheck = "123456789";
  EXPECT_EQ(crc32(std::as_bytes(std::span(kCheck.data(), kCheck.size()))), 0xCBF43926U);

  std::mt19937 random(3);
  Bytes data(1000);
  for (auto& b : data) {
    b = static_cast<std::byte>(random());
  }
  const auto reference = referenceCrc32(data);
  EXPECT_EQ(crc32(data), reference);
  const auto chained = crc32Update(crc32(std::span(data).first(333)), std::span(data).subspan(333));
  EXPECT_EQ(chained, reference);
}

TEST(Wire, HeaderLayoutIsAsDocumented) {
  Bytes buffer(64);
  const auto message = encodeEmpty(MessageType::kStopStream, buffer);
  ASSERT_TRUE(message.has_value());
  ASSERT_EQ(message->size(), kHeaderBytes);
  const std::array<std::uint8_t, 12> expected = {'S', 'M', 'X', 'P', 1, 4, 0, 0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(std::to_integer<std::uint8_t>((*message)[i]), expected[i]) << "byte " << i;
  }
  const auto crc = referenceCrc32(message->first(12));
  const std::uint32_t stored = std::to_integer<std::uint32_t>((*message)[12]) |
                               std::to_integer<std::uint32_t>((*message)[13]) << 8 |
                               std::to_integer<std::uint32_t>((*message)[14]) << 16 |
                               std::to_integer<std::uint32_t>((*message)[15]) << 24;
  EXPECT_EQ(stored, crc);
}

TEST(Messages, EveryMessageRoundTrips) {
  Capabilities caps{.board = "sim",
                    .firmwareVersion = "0.1.0",
                    .halBackend = "sim",
                    .depthUnitNm = 100'000,
                    .cameras = 2,
                    .projectors = 3,
                    .width = 640,
                    .height = 480,
                    .fps = 30,
                    .compressionsMask = 3,
                    .rigJson = R"({"format": "stripemux-rig/1"})"};
  Statistics stats{.uptimeMs = 1,
                   .framesCaptured = 2,
                   .framesDecoded = 3,
                   .framesSent = 4,
                   .framesDropped = 5,
                   .captureErrors = 6,
                   .protocolErrors = 7,
                   .decodeTimeUsLast = 8,
                   .decodeTimeUsMean = 9};
  StreamParser parser(1 << 16);
  for (const Bytes& bytes :
       {encoded(Hello{"stripemux test"}), encoded(caps), encoded(StartStream{Compression::kNone}),
        encoded(stats), encoded(ErrorMessage{ErrorCode::kBusy, "another host is connected"})}) {
    ASSERT_EQ(parser.feed(bytes), bytes.size());
  }
  const auto messages = parseAll(parser);
  ASSERT_EQ(messages.size(), 5U);
  EXPECT_EQ(decodeHello(messages[0].payload)->client, "stripemux test");
  const auto gotCaps = decodeCapabilities(messages[1].payload);
  ASSERT_TRUE(gotCaps.has_value());
  EXPECT_EQ(gotCaps->board, "sim");
  EXPECT_EQ(gotCaps->firmwareVersion, "0.1.0");
  EXPECT_EQ(gotCaps->projectors, 3);
  EXPECT_EQ(gotCaps->width, 640);
  EXPECT_EQ(gotCaps->height, 480);
  EXPECT_EQ(gotCaps->rigJson, caps.rigJson);
  EXPECT_EQ(decodeStartStream(messages[2].payload)->compression, Compression::kNone);
  const auto gotStats = decodeStatistics(messages[3].payload);
  ASSERT_TRUE(gotStats.has_value());
  EXPECT_EQ(gotStats->framesDropped, 5U);
  EXPECT_EQ(gotStats->decodeTimeUsMean, 9U);
  const auto error = decodeError(messages[4].payload);
  ASSERT_TRUE(error.has_value());
  EXPECT_EQ(error->code, ErrorCode::kBusy);
  EXPECT_EQ(error->text, "another host is connected");
}

TEST(Messages, TruncatedOrPaddedPayloadsAreMalformed) {
  const Bytes caps = encoded(
      Capabilities{.board = "b", .firmwareVersion = "v", .halBackend = "sim", .rigJson = "{}"});
  const auto payload = std::span(caps).subspan(kHeaderBytes);
  for (std::size_t cut = 0; cut < payload.size(); ++cut) {
    const auto result = decodeCapabilities(payload.first(cut));
    ASSERT_FALSE(result.has_value()) << "cut at " << cut;
    EXPECT_EQ(result.error().code, ProtocolErrc::kMalformed);
  }
  Bytes padded(payload.begin(), payload.end());
  padded.push_back(std::byte{0});
  EXPECT_FALSE(decodeCapabilities(padded).has_value());
  EXPECT_FALSE(decodeStartStream(std::array{std::byte{7}}).has_value());  // no compression 7
  EXPECT_FALSE(decodeEmpty(std::array{std::byte{0}}).has_value());
}

TEST(RangeFrame, RvlBytesAreTheDocumentedCode) {
  // Given the row [0, 0, 5, 6]: zeros 2, values 2, then zigzag(5 - 0) = 10 = 0b001'010 and
  // zigzag(6 - 5) = 2. Nibbles 2, 2, (8|2), 1, 2 and a zero pad nibble.
  std::array<std::uint16_t, 4> pixels = {0, 0, 5, 6};
  const auto plane = algo::ConstDepthPlane::packed(pixels, 4, 1).value();
  std::array<std::byte, 16> out{};
  const auto bytes = rvlEncode(plane, out);
  ASSERT_TRUE(bytes.has_value());
  ASSERT_EQ(*bytes, 3U);
  EXPECT_EQ(out[0], std::byte{0x22});
  EXPECT_EQ(out[1], std::byte{0xA1});
  EXPECT_EQ(out[2], std::byte{0x20});
  std::array<std::uint16_t, 4> back{};
  ASSERT_TRUE(rvlDecode(std::span(out).first(3), back).has_value());
  EXPECT_EQ(back, pixels);
}

// A depth image like a scan: smooth surfaces, holes, edges; deterministic.
std::vector<std::uint16_t> sceneLikeDepth(int width, int height, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> noise(-3, 3);
  std::vector<std::uint16_t> depth(static_cast<std::size_t>(width) *
                                   static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const bool hole = (x / 17 + y / 13) % 7 == 0;
      const int z = 9000 + 4 * x - 3 * y + (x > width / 2 ? 1500 : 0) + noise(random);
      depth[static_cast<std::size_t>(y * width + x)] = hole ? 0 : static_cast<std::uint16_t>(z);
    }
  }
  depth.front() = 65535;  // extremes
  depth.back() = 1;
  return depth;
}

TEST(RangeFrame, RoundTripsExactlyThroughTheParser) {
  for (const auto& [width, height] : {std::pair{640, 480}, std::pair{1, 1}, std::pair{7, 3}}) {
    const auto depth = sceneLikeDepth(width, height, 11);
    const auto plane = algo::ConstDepthPlane::packed(depth, width, height).value();
    Bytes buffer(rangeFrameBound(width, height));
    const RangeFrameHeader header{.camera = 1,
                                  .compression = Compression::kRvl,
                                  .frame = 42,
                                  .captureTimestampNs = 123456789,
                                  .sentTimestampNs = 123999999,
                                  .depthUnitNm = 100'000,
                                  .decodeTimeUs = 777};
    const auto message = encodeRangeFrame(header, plane, buffer);
    ASSERT_TRUE(message.has_value());
    StreamParser parser(kMaxPayloadBytes);
    // Byte by byte for the small images, in uneven chunks for the big one.
    const std::size_t chunk = width == 640 ? 1013 : 1;
    std::vector<Message> messages;
    for (std::size_t at = 0; at < message->size(); at += chunk) {
      parser.feed(message->subspan(at, std::min(chunk, message->size() - at)));
      auto got = parseAll(parser);
      messages.insert(messages.end(), got.begin(), got.end());
      if (!got.empty()) {
        break;  // the payload view is only valid until the parser moves on
      }
    }
    ASSERT_EQ(messages.size(), 1U);
    const auto frame = decodeRangeFrame(messages[0].payload);
    ASSERT_TRUE(frame.has_value());
    EXPECT_EQ(frame->header.camera, 1);
    EXPECT_EQ(frame->header.frame, 42U);
    EXPECT_EQ(frame->header.captureTimestampNs, 123456789);
    EXPECT_EQ(frame->header.width, width);
    EXPECT_EQ(frame->header.height, height);
    std::vector<std::uint16_t> back(depth.size());
    ASSERT_TRUE(decodeRangeDepth(*frame, back).has_value());
    EXPECT_EQ(back, depth);
    if (width == 640) {
      EXPECT_EQ(frame->header.compression, Compression::kRvl);
      EXPECT_LT(message->size(), depth.size());  // well under 2 bytes per pixel
    }
  }
}

TEST(RangeFrame, IncompressibleDepthIsSentRaw) {
  std::mt19937 random(5);
  std::vector<std::uint16_t> depth(64 * 48);
  for (auto& z : depth) {
    z = static_cast<std::uint16_t>(1 + random() % 65535);
  }
  const auto plane = algo::ConstDepthPlane::packed(depth, 64, 48).value();
  Bytes buffer(rangeFrameBound(64, 48));
  const auto message = encodeRangeFrame({.compression = Compression::kRvl}, plane, buffer);
  ASSERT_TRUE(message.has_value());
  const auto frame = decodeRangeFrame(message->subspan(kHeaderBytes));
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->header.compression, Compression::kNone);
  std::vector<std::uint16_t> back(depth.size());
  ASSERT_TRUE(decodeRangeDepth(*frame, back).has_value());
  EXPECT_EQ(back, depth);
}

TEST(Rvl, RejectsMalformedStreams) {
  std::array<std::uint16_t, 4> out{};
  const auto code = [&](std::initializer_list<std::uint8_t> bytes) {
    std::vector<std::byte> in;
    for (const auto b : bytes) {
      in.push_back(static_cast<std::byte>(b));
    }
    return rvlDecode(in, out);
  };
  EXPECT_TRUE(code({0x22, 0xA1, 0x20}).has_value());
  EXPECT_FALSE(code({0x22, 0xA1}).has_value());              // truncated in the last value
  EXPECT_FALSE(code({0x22, 0xA1, 0x20, 0x00}).has_value());  // trailing byte
  EXPECT_FALSE(code({0x22, 0xA1, 0x21}).has_value());        // non-zero pad nibble
  EXPECT_FALSE(code({0x00}).has_value());                    // a pair that makes no progress
  EXPECT_FALSE(code({0x50}).has_value());                    // 5 zeros in a 4-pixel image
  EXPECT_FALSE(code({0x04, 0x9F, 0xFF, 0xF7}).has_value());  // value far above 65535
  EXPECT_FALSE(code({0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x00}).has_value());  // over 32 bits
}

TEST(StreamParser, SkipsGarbageAndBadMessagesAndKeepsTheGoodOnes) {
  const Bytes hello = encoded(Hello{"a"});
  Bytes badCrc = encoded(Hello{"b"});
  badCrc.back() ^= std::byte{1};
  Bytes badVersion = encoded(Hello{"c"});
  badVersion[4] = std::byte{9};
  Bytes oversized = encoded(Hello{"d"});
  oversized[11] = std::byte{0x7F};  // length ~2 GB
  const Bytes garbage = {std::byte{'x'}, std::byte{'S'}, std::byte{'M'}, std::byte{0}};

  Bytes stream;
  for (const Bytes* part : std::initializer_list<const Bytes*>{&garbage, &hello, &badCrc, &hello,
                                                               &badVersion, &oversized, &hello}) {
    stream.insert(stream.end(), part->begin(), part->end());
  }
  StreamParser parser(1024);
  std::vector<ProtocolErrc> errors;
  std::vector<std::string_view> clients;
  for (std::size_t at = 0; at < stream.size(); at += 5) {
    parser.feed(std::span(stream).subspan(at, std::min<std::size_t>(5, stream.size() - at)));
    for (const Message& m : parseAll(parser, &errors)) {
      clients.push_back(decodeHello(m.payload)->client);
    }
  }
  EXPECT_EQ(clients, (std::vector<std::string_view>{"a", "a", "a"}));
  EXPECT_EQ(parser.counters().messages, 3U);
  const auto count = [&](ProtocolErrc code) { return std::ranges::count(errors, code); };
  EXPECT_GE(count(ProtocolErrc::kBadMagic), 1);
  EXPECT_EQ(count(ProtocolErrc::kBadCrc), 1);
  EXPECT_EQ(count(ProtocolErrc::kUnsupportedVersion), 1);
  EXPECT_EQ(count(ProtocolErrc::kOversized), 1);
  EXPECT_EQ(parser.counters().errors, errors.size());
}

TEST(StreamParser, RandomBytesNeitherCrashNorStall) {
  std::mt19937 random(9);
  StreamParser parser(256);
  std::uint64_t bytesIn = 0;
  for (int round = 0; round < 2000; ++round) {
    Bytes chunk(1 + random() % 64);
    for (auto& b : chunk) {
      // Mostly magic bytes, so headers get parsed often.
      b = random() % 4 == 0 ? kMagic[random() % 4] : static_cast<std::byte>(random());
    }
    bytesIn += parser.feed(chunk);
    int steps = 0;
    while (true) {
      auto next = parser.next();
      ASSERT_LT(++steps, 10000) << "the parser stalls";
      if (next && !next->has_value()) {
        break;
      }
    }
  }
  EXPECT_GT(parser.counters().bytesSkipped, bytesIn / 2);
}

TEST(Protocol, EncodingAndParsingARangeFrameNeverAllocates) {
  const auto depth = sceneLikeDepth(640, 480, 2);
  const auto plane = algo::ConstDepthPlane::packed(depth, 640, 480).value();
  Bytes buffer(rangeFrameBound(640, 480));
  std::vector<std::uint16_t> back(depth.size());
  StreamParser parser(kMaxPayloadBytes);

  const test::AllocationCounter counter;
  const auto message = encodeRangeFrame({.compression = Compression::kRvl}, plane, buffer);
  ASSERT_TRUE(message.has_value());
  ASSERT_EQ(parser.feed(*message), message->size());
  const auto parsed = parser.next();
  ASSERT_TRUE(parsed.has_value() && parsed->has_value());
  const auto frame = decodeRangeFrame((*parsed)->payload);
  ASSERT_TRUE(frame.has_value());
  ASSERT_TRUE(decodeRangeDepth(*frame, back).has_value());
  EXPECT_EQ(counter.allocations(), 0U);
  EXPECT_EQ(back, depth);
}

// A confidence plane like a scan's: 0 exactly where `depth` is 0, 1…255 elsewhere, changing
// slowly over surfaces and jumping at their edges.
std::vector<std::uint8_t> confidenceOf(const std::vector<std::uint16_t>& depth) {
  std::vector<std::uint8_t> confidence(depth.size());
  for (std::size_t i = 0; i < depth.size(); ++i) {
    confidence[i] = static_cast<std::uint8_t>(depth[i] == 0 ? 0 : 1 + (depth[i] / 8) % 255);
  }
  return confidence;
}

TEST(StartStream, WithoutOptionsIsTheOneByteRequestOfEveryDevice) {
  // Given a request without the confidence option, Then its payload is the compression only.
  const Bytes plain = encoded(StartStream{.compression = Compression::kRvl});
  ASSERT_EQ(plain.size(), kHeaderBytes + 1);
  EXPECT_EQ(plain[kHeaderBytes], std::byte{1});
  EXPECT_FALSE(decodeStartStream(std::span(plain).subspan(kHeaderBytes))->confidence);
  // With it: a second byte, bit 0.
  const Bytes asking = encoded(StartStream{.compression = Compression::kNone, .confidence = true});
  ASSERT_EQ(asking.size(), kHeaderBytes + 2);
  EXPECT_EQ(asking[kHeaderBytes + 1], std::byte{1});
  const auto got = decodeStartStream(std::span(asking).subspan(kHeaderBytes));
  ASSERT_TRUE(got.has_value());
  EXPECT_TRUE(got->confidence);
  EXPECT_EQ(got->compression, Compression::kNone);
  // Unknown option bits and a third byte are refused.
  EXPECT_FALSE(decodeStartStream(std::array{std::byte{1}, std::byte{2}}).has_value());
  EXPECT_FALSE(decodeStartStream(std::array{std::byte{1}, std::byte{1}, std::byte{0}}).has_value());
}

TEST(RangeFrameConfidence, RoundTripsExactlyThroughTheParser) {
  for (const Compression compression : {Compression::kRvl, Compression::kNone}) {
    for (const auto& [width, height] : {std::pair{640, 480}, std::pair{1, 1}, std::pair{7, 3}}) {
      const auto depth = sceneLikeDepth(width, height, 3);
      const auto confidence = confidenceOf(depth);
      const auto depthPlane = algo::ConstDepthPlane::packed(depth, width, height).value();
      const auto confidencePlane =
          algo::ImageView<const std::uint8_t>::packed(confidence, width, height).value();
      Bytes buffer(rangeFrameBound(width, height, true));
      const auto message = encodeRangeFrame(
          {.camera = 1, .compression = compression, .frame = 7, .depthUnitNm = 50'000}, depthPlane,
          confidencePlane, buffer);
      ASSERT_TRUE(message.has_value());
      StreamParser parser(kMaxPayloadBytes);
      ASSERT_EQ(parser.feed(*message), message->size());
      const auto parsed = parser.next();
      ASSERT_TRUE(parsed.has_value() && parsed->has_value());
      ASSERT_EQ((*parsed)->type, MessageType::kRangeFrameConfidence);
      const auto frame = decodeRangeFrame((*parsed)->payload, MessageType::kRangeFrameConfidence);
      ASSERT_TRUE(frame.has_value());
      EXPECT_TRUE(frame->hasConfidence);
      EXPECT_EQ(frame->header.frame, 7U);
      EXPECT_EQ(frame->header.depthUnitNm, 50'000U);
      std::vector<std::uint16_t> depthBack(depth.size());
      std::vector<std::uint8_t> confidenceBack(depth.size());
      ASSERT_TRUE(decodeRangeDepth(*frame, depthBack).has_value());
      ASSERT_TRUE(decodeRangeConfidence(*frame, confidenceBack).has_value());
      EXPECT_EQ(depthBack, depth);
      EXPECT_EQ(confidenceBack, confidence);
      if (width == 640) {
        EXPECT_EQ(frame->header.compression, compression);
      }
      if (width == 640 && compression == Compression::kNone) {
        EXPECT_EQ(message->size(), kHeaderBytes + 42 + 3 * depth.size());
      }
    }
  }
}

TEST(RangeFrameConfidence, IncompressibleConfidenceSendsBothPlanesRaw) {
  // Given smooth depth but a confidence that changes at every pixel by more than RVL saves.
  const auto depth = sceneLikeDepth(64, 48, 9);
  std::vector<std::uint8_t> confidence(depth.size());
  std::mt19937 random(6);
  for (auto& c : confidence) {
    c = static_cast<std::uint8_t>(1 + random() % 255);
  }
  std::vector<std::uint16_t> full(depth.size(), 1000);  // no zeros: every confidence counts
  const auto depthPlane = algo::ConstDepthPlane::packed(full, 64, 48).value();
  const auto confidencePlane =
      algo::ImageView<const std::uint8_t>::packed(confidence, 64, 48).value();
  Bytes buffer(rangeFrameBound(64, 48, true));
  const auto message =
      encodeRangeFrame({.compression = Compression::kRvl}, depthPlane, confidencePlane, buffer);
  ASSERT_TRUE(message.has_value());
  const auto frame =
      decodeRangeFrame(message->subspan(kHeaderBytes), MessageType::kRangeFrameConfidence);
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->header.compression, Compression::kNone);
  std::vector<std::uint8_t> back(confidence.size());
  ASSERT_TRUE(decodeRangeConfidence(*frame, back).has_value());
  EXPECT_EQ(back, confidence);
}

TEST(RangeFrameConfidence, HostileSizesAreRefusedNamingThePlane) {
  const auto depth = sceneLikeDepth(16, 8, 1);
  const auto confidence = confidenceOf(depth);
  const auto depthPlane = algo::ConstDepthPlane::packed(depth, 16, 8).value();
  const auto confidencePlane =
      algo::ImageView<const std::uint8_t>::packed(confidence, 16, 8).value();
  const auto payloadOf = [&](Compression compression) {
    Bytes buffer(rangeFrameBound(16, 8, true));
    const auto message =
        encodeRangeFrame({.compression = compression}, depthPlane, confidencePlane, buffer);
    EXPECT_TRUE(message.has_value());
    return Bytes(message->begin() + kHeaderBytes, message->end());
  };
  constexpr auto kType = MessageType::kRangeFrameConfidence;
  constexpr std::size_t kDepthBytesAt = 38;  // after the header fields of message 5

  // A raw confidence plane one byte short or long.
  Bytes raw = payloadOf(Compression::kNone);
  ASSERT_TRUE(decodeRangeFrame(raw, kType).has_value());
  for (const bool longer : {false, true}) {
    Bytes bad = raw;
    longer ? bad.push_back(std::byte{9}) : bad.pop_back();
    const auto frame = decodeRangeFrame(bad, kType);
    ASSERT_FALSE(frame.has_value());
    EXPECT_STREQ(frame.error().message,
                 "range frame: raw confidence plane size does not match width x height");
  }
  // A depth size that runs past the payload.
  Bytes past = raw;
  past[kDepthBytesAt + 3] = std::byte{0x7F};
  const auto pastFrame = decodeRangeFrame(past, kType);
  ASSERT_FALSE(pastFrame.has_value());
  EXPECT_STREQ(pastFrame.error().message,
               "range frame: depth size runs past the end of the payload");

  // Every cut of an RVL frame fails somewhere: the frame, its depth or its confidence.
  const Bytes rvl = payloadOf(Compression::kRvl);
  std::vector<std::uint16_t> depthBack(depth.size());
  std::vector<std::uint8_t> confidenceBack(depth.size());
  for (std::size_t cut = 0; cut < rvl.size(); ++cut) {
    const auto frame = decodeRangeFrame(std::span(rvl).first(cut), kType);
    const bool whole = frame && decodeRangeDepth(*frame, depthBack) &&
                       decodeRangeConfidence(*frame, confidenceBack);
    EXPECT_FALSE(whole) << "cut at " << cut;
  }
  // A depth-only frame has no confidence to read; a buffer of another size is refused.
  Bytes depthOnlyBuffer(rangeFrameBound(16, 8));
  const auto depthOnly =
      encodeRangeFrame({.compression = Compression::kRvl}, depthPlane, depthOnlyBuffer);
  ASSERT_TRUE(depthOnly.has_value());
  const auto plain = decodeRangeFrame(depthOnly->subspan(kHeaderBytes));
  ASSERT_TRUE(plain.has_value());
  EXPECT_FALSE(plain->hasConfidence);
  EXPECT_FALSE(decodeRangeConfidence(*plain, confidenceBack).has_value());
  const auto full = decodeRangeFrame(rvl, kType);
  ASSERT_TRUE(full.has_value());
  std::vector<std::uint8_t> wrongSize(depth.size() + 1);
  EXPECT_FALSE(decodeRangeConfidence(*full, wrongSize).has_value());
  // Planes of different sizes are not encoded.
  Bytes buffer(rangeFrameBound(16, 8, true));
  const auto smaller =
      algo::ImageView<const std::uint8_t>::packed(std::span(confidence).first(64), 8, 8).value();
  EXPECT_FALSE(encodeRangeFrame({}, depthPlane, smaller, buffer).has_value());
}

TEST(Rvl, EightBitPlanesRefuseValuesAbove255) {
  // Given one pixel whose coded value is 256 (zeros 0, values 1, zigzag 512 = 0o1000).
  const std::array<std::byte, 3> in = {std::byte{0x01}, std::byte{0x88}, std::byte{0x81}};
  std::array<std::uint16_t, 1> wide{};
  ASSERT_TRUE(rvlDecode(std::span(in).first(3), wide).has_value());
  EXPECT_EQ(wide[0], 256);
  std::array<std::uint8_t, 1> narrow{};
  EXPECT_FALSE(rvlDecode(in, narrow).has_value());
}

TEST(Protocol, EncodingAndParsingAConfidenceFrameNeverAllocates) {
  const auto depth = sceneLikeDepth(640, 480, 2);
  const auto confidence = confidenceOf(depth);
  const auto depthPlane = algo::ConstDepthPlane::packed(depth, 640, 480).value();
  const auto confidencePlane =
      algo::ImageView<const std::uint8_t>::packed(confidence, 640, 480).value();
  Bytes buffer(rangeFrameBound(640, 480, true));
  std::vector<std::uint8_t> back(depth.size());
  StreamParser parser(kMaxPayloadBytes);

  const test::AllocationCounter counter;
  const auto message =
      encodeRangeFrame({.compression = Compression::kRvl}, depthPlane, confidencePlane, buffer);
  ASSERT_TRUE(message.has_value());
  ASSERT_EQ(parser.feed(*message), message->size());
  const auto parsed = parser.next();
  ASSERT_TRUE(parsed.has_value() && parsed->has_value());
  const auto frame = decodeRangeFrame((*parsed)->payload, (*parsed)->type);
  ASSERT_TRUE(frame.has_value());
  ASSERT_TRUE(decodeRangeConfidence(*frame, back).has_value());
  EXPECT_EQ(counter.allocations(), 0U);
  EXPECT_EQ(back, confidence);
}

}  // namespace
}  // namespace smx::protocol
