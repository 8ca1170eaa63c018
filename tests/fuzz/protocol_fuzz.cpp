// libFuzzer target for everything that reads bytes from the other side of the link: the stream
// parser (framing, CRC, resynchronisation), every message decoder and RVL. Besides "no crash, no
// sanitizer report" it checks that the parser always makes progress and that a range frame that
// decodes re-encodes to the same depth (and confidence), and a raw-frame band to the same bytes.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "smx/protocol/messages.hpp"
#include "smx/protocol/rvl.hpp"
#include "smx/protocol/stream_parser.hpp"

namespace {

using namespace smx::protocol;

[[noreturn]] void broken() {
  std::abort();
}

void checkRangeFrame(const Message& message) {
  const auto frame = decodeRangeFrame(message.payload, message.type);
  if (!frame) {
    return;
  }
  const std::size_t pixels = std::size_t{frame->header.width} * frame->header.height;
  if (pixels > (1U << 20U)) {
    return;
  }
  std::vector<std::uint16_t> depth(pixels);
  std::vector<std::uint8_t> confidence(frame->hasConfidence ? pixels : 0);
  if (!decodeRangeDepth(*frame, depth) ||
      (frame->hasConfidence && !decodeRangeConfidence(*frame, confidence))) {
    return;
  }
  // What decoded must survive a round trip exactly.
  const int width = frame->header.width;
  const int height = frame->header.height;
  const auto plane = *smx::algo::ConstDepthPlane::packed(depth, width, height);
  std::vector<std::byte> buffer(rangeFrameBound(width, height, frame->hasConfidence));
  const auto again = frame->hasConfidence
                         ? encodeRangeFrame(frame->header, plane,
                                            *smx::algo::ImageView<const std::uint8_t>::packed(
                                                confidence, width, height),
                                            buffer)
                         : encodeRangeFrame(frame->header, plane, buffer);
  if (!again) {
    broken();
  }
  const auto reframe = decodeRangeFrame(again->subspan(kHeaderBytes), message.type);
  std::vector<std::uint16_t> back(pixels);
  std::vector<std::uint8_t> confidenceBack(confidence.size());
  if (!reframe || !decodeRangeDepth(*reframe, back) || back != depth) {
    broken();
  }
  if (frame->hasConfidence &&
      (!decodeRangeConfidence(*reframe, confidenceBack) || confidenceBack != confidence)) {
    broken();
  }
}

// A band that decodes is inside its frame, and re-encodes to the very same payload.
void checkRawFrame(const Message& message) {
  const auto band = decodeRawFrame(message.payload);
  if (!band) {
    return;
  }
  const RawFrameHeader& h = band->header;
  if (std::size_t{h.firstRow} + h.rows > h.height ||
      band->pixels.size() != 3 * std::size_t{h.width} * h.rows) {
    broken();
  }
  // The band as a frame of its own rows (firstRow 0), then compared field by field.
  std::vector<smx::algo::Rgb8> pixels(std::size_t{h.width} * h.rows);
  std::memcpy(pixels.data(), band->pixels.data(), band->pixels.size());
  RawFrameHeader local = h;
  local.firstRow = 0;
  std::vector<std::byte> buffer(kHeaderBytes + kRawFrameHeaderBytes + band->pixels.size());
  const auto again =
      encodeRawFrame(local, *smx::algo::ConstRgbView::packed(pixels, h.width, h.rows), buffer);
  if (!again) {
    broken();
  }
  const auto back = decodeRawFrame(again->subspan(kHeaderBytes));
  if (!back || back->header.camera != h.camera || back->header.projectorsMask != h.projectorsMask ||
      back->header.capture != h.capture ||
      back->header.captureTimestampNs != h.captureTimestampNs ||
      !std::equal(back->pixels.begin(), back->pixels.end(), band->pixels.begin(),
                  band->pixels.end())) {
    broken();
  }
}

// A turntable state or turn request that decodes re-encodes to the very same payload.
void checkTurntable(const Message& message) {
  const auto state = decodeTurntable(message.payload);
  if (!state) {
    return;
  }
  std::array<std::byte, kHeaderBytes + kTurntablePayloadBytes> buffer{};
  const auto again = encode(*state, buffer);
  if (!again || !std::ranges::equal(again->subspan(kHeaderBytes), message.payload)) {
    broken();
  }
}

void checkTurnTurntable(const Message& message) {
  const auto turn = decodeTurnTurntable(message.payload);
  if (!turn) {
    return;
  }
  std::array<std::byte, kHeaderBytes + 9> buffer{};
  const auto again = encode(*turn, buffer);
  if (!again || !std::ranges::equal(again->subspan(kHeaderBytes), message.payload)) {
    broken();
  }
}

void decodeAny(const Message& message) {
  switch (message.type) {
    case MessageType::kHello:
      (void)decodeHello(message.payload);
      break;
    case MessageType::kCapabilities:
      (void)decodeCapabilities(message.payload);
      break;
    case MessageType::kStartStream:
      (void)decodeStartStream(message.payload);
      break;
    case MessageType::kStatistics:
      (void)decodeStatistics(message.payload);
      break;
    case MessageType::kError:
      (void)decodeError(message.payload);
      break;
    case MessageType::kRangeFrame:
    case MessageType::kRangeFrameConfidence:
      checkRangeFrame(message);
      break;
    case MessageType::kCaptureRaw:
      (void)decodeCaptureRaw(message.payload);
      break;
    case MessageType::kRawFrame:
      checkRawFrame(message);
      break;
    case MessageType::kConfig:
      (void)decodeConfig(message.payload);
      break;
    case MessageType::kSetConfig:
      (void)decodeSetConfig(message.payload);
      break;
    case MessageType::kTurntable:
      checkTurntable(message);
      break;
    case MessageType::kTurnTurntable:
      checkTurnTurntable(message);
      break;
    default:
      (void)decodeEmpty(message.payload);
      break;
  }
}

// A random CRC almost never matches, so half the inputs are framed here with correct headers:
// records of [type, length (2 bytes), payload] become sealed messages, and the decoders behind
// the CRC check get fuzzed too.
std::vector<std::byte> framed(std::span<const std::byte> records) {
  std::vector<std::byte> stream;
  while (records.size() >= 3) {
    const auto type = static_cast<MessageType>(std::to_integer<std::uint8_t>(records[0]) % 32U);
    const std::size_t length = std::min<std::size_t>(
        records.size() - 3,
        std::to_integer<std::size_t>(records[1]) | std::to_integer<std::size_t>(records[2]) << 8U);
    std::vector<std::byte> message(kHeaderBytes + length);
    std::copy_n(records.begin() + 3, length, message.begin() + kHeaderBytes);
    if (!sealMessage(message, type, length)) {
      broken();
    }
    stream.insert(stream.end(), message.begin(), message.end());
    records = records.subspan(3 + length);
  }
  return stream;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) {
    return 0;
  }
  const auto input = std::as_bytes(std::span(data + 1, size - 1));
  const std::size_t chunk = data[0] % 64U + 1U;  // how the stream arrives
  const std::vector<std::byte> sealed =
      (data[0] & 0x80U) != 0 ? framed(input) : std::vector<std::byte>();
  const std::span<const std::byte> bytes = (data[0] & 0x80U) != 0 ? sealed : input;

  StreamParser parser(1U << 16U);
  for (std::size_t at = 0; at < bytes.size();) {
    at += parser.feed(bytes.subspan(at, std::min(chunk, bytes.size() - at)));
    // Each call either returns a message or an error (both consume bytes) or asks for more.
    for (std::size_t steps = 0;; ++steps) {
      if (steps > bytes.size() + 1) {
        broken();  // stalled
      }
      const auto next = parser.next();
      if (next && !next->has_value()) {
        break;
      }
      if (next) {
        decodeAny(**next);
      }
    }
  }
  // RVL alone, on the raw bytes, into an image of a size the input chooses.
  std::vector<std::uint16_t> image(std::size_t{data[0]} * 7U + 1U);
  (void)rvlDecode(input, image);
  return 0;
}
