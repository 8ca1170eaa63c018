#include "smx/protocol/messages.hpp"

#include <algorithm>

#include "payload.hpp"
#include "smx/protocol/byte_io.hpp"
#include "smx/protocol/rvl.hpp"

namespace smx::protocol {

namespace {

constexpr std::uint8_t kKnownCompressions = (1U << 0U) | (1U << 1U);

using detail::build;
using detail::finished;

bool validCompression(std::uint8_t value) {
  return value <= 1;
}

// start-stream's optional second byte.
constexpr std::uint8_t kOptionConfidence = 1U << 0U;

void writeFrameHeader(ByteWriter& w, const RangeFrameHeader& header) {
  w.put(header.camera);
  w.put(static_cast<std::uint8_t>(header.compression));
  w.put(header.width);
  w.put(header.height);
  w.put(header.frame);
  w.put(static_cast<std::uint64_t>(header.captureTimestampNs));
  w.put(static_cast<std::uint64_t>(header.sentTimestampNs));
  w.put(header.depthUnitNm);
  w.put(header.decodeTimeUs);
}

template <class Pixel>
void writeRaw(ByteWriter& w, algo::ImageView<const Pixel> plane) {
  for (int y = 0; y < plane.height(); ++y) {
    for (const Pixel value : plane.row(y)) {
      w.put(value);
    }
  }
}

// RVL into at most the raw size of `plane`; on overflow marks the writer failed (then the caller
// sends the frame raw).
template <class Pixel>
void writeRvl(ByteWriter& w, algo::ImageView<const Pixel> plane) {
  const std::size_t rawBytes = sizeof(Pixel) * static_cast<std::size_t>(plane.width()) *
                               static_cast<std::size_t>(plane.height());
  const std::span<std::byte> room = w.remaining();
  const auto packed = rvlEncode(plane, room.first(std::min(room.size(), rawBytes)));
  w.advance(packed ? *packed : room.size() + 1);
}

// The size prefix of the depth in a frame with confidence: written once the depth's bytes are
// known, right before them.
template <class Pixel>
void writeRvlSized(ByteWriter& w, algo::ImageView<const Pixel> plane) {
  const std::size_t rawBytes = sizeof(Pixel) * static_cast<std::size_t>(plane.width()) *
                               static_cast<std::size_t>(plane.height());
  const std::span<std::byte> room = w.remaining();
  if (room.size() < sizeof(std::uint32_t)) {
    w.advance(room.size() + 1);
    return;
  }
  const std::span<std::byte> after = room.subspan(sizeof(std::uint32_t));
  const auto packed = rvlEncode(plane, after.first(std::min(after.size(), rawBytes)));
  if (!packed) {
    w.advance(room.size() + 1);
    return;
  }
  w.put(static_cast<std::uint32_t>(*packed));
  w.advance(*packed);
}

ProtocolResult<std::span<const std::byte>> encodeFrame(
    RangeFrameHeader header, algo::ConstDepthPlane depth,
    const algo::ImageView<const std::uint8_t>* confidence, std::span<std::byte> out) {
  header.width = static_cast<std::uint16_t>(depth.width());
  header.height = static_cast<std::uint16_t>(depth.height());
  if (depth.width() > 0xFFFF || depth.height() > 0xFFFF) {
    return protocolFail(ProtocolErrc::kBufferTooSmall, "range image is larger than 65535 px");
  }
  if (confidence != nullptr &&
      (confidence->width() != depth.width() || confidence->height() != depth.height())) {
    return protocolFail(ProtocolErrc::kMalformed, "confidence plane is not the depth's size");
  }
  const MessageType type =
      confidence != nullptr ? MessageType::kRangeFrameConfidence : MessageType::kRangeFrame;
  if (header.compression == Compression::kRvl) {
    auto rvl = build(type, out, [&](ByteWriter& w) {
      writeFrameHeader(w, header);
      if (confidence == nullptr) {
        writeRvl(w, depth);
        return;
      }
      writeRvlSized(w, depth);
      writeRvl(w, *confidence);
    });
    if (rvl) {
      return rvl;
    }
    header.compression = Compression::kNone;
  }
  return build(type, out, [&](ByteWriter& w) {
    writeFrameHeader(w, header);
    if (confidence != nullptr) {
      w.put(static_cast<std::uint32_t>(2 * static_cast<std::size_t>(depth.width()) *
                                       static_cast<std::size_t>(depth.height())));
    }
    writeRaw(w, depth);
    if (confidence != nullptr) {
      writeRaw(w, *confidence);
    }
  });
}

}  // namespace

const char* toString(Compression compression) {
  switch (compression) {
    case Compression::kNone:
      return "none";
    case Compression::kRvl:
      return "rvl";
  }
  return "unknown";
}

ProtocolResult<std::span<const std::byte>> encode(const Hello& m, std::span<std::byte> out) {
  return build(MessageType::kHello, out, [&](ByteWriter& w) { w.putString16(m.client); });
}

ProtocolResult<std::span<const std::byte>> encode(const Capabilities& m, std::span<std::byte> out) {
  return build(MessageType::kCapabilities, out, [&](ByteWriter& w) {
    w.putString16(m.board);
    w.putString16(m.firmwareVersion);
    w.putString16(m.halBackend);
    w.put(m.depthUnitNm);
    w.put(m.cameras);
    w.put(m.projectors);
    w.put(m.width);
    w.put(m.height);
    w.put(m.fps);
    w.put(m.compressionsMask);
    w.putString32(m.rigJson);
  });
}

ProtocolResult<std::span<const std::byte>> encode(const StartStream& m, std::span<std::byte> out) {
  return build(MessageType::kStartStream, out, [&](ByteWriter& w) {
    w.put(static_cast<std::uint8_t>(m.compression));
    if (m.confidence) {
      w.put(kOptionConfidence);
    }
  });
}

ProtocolResult<std::span<const std::byte>> encode(const Statistics& m, std::span<std::byte> out) {
  return build(MessageType::kStatistics, out, [&](ByteWriter& w) {
    w.put(m.uptimeMs);
    w.put(m.framesCaptured);
    w.put(m.framesDecoded);
    w.put(m.framesSent);
    w.put(m.framesDropped);
    w.put(m.captureErrors);
    w.put(m.protocolErrors);
    w.put(m.decodeTimeUsLast);
    w.put(m.decodeTimeUsMean);
  });
}

ProtocolResult<std::span<const std::byte>> encode(const ErrorMessage& m, std::span<std::byte> out) {
  return build(MessageType::kError, out, [&](ByteWriter& w) {
    w.put(static_cast<std::uint16_t>(m.code));
    w.putString16(m.text);
  });
}

ProtocolResult<std::span<const std::byte>> encode(const CaptureRaw& m, std::span<std::byte> out) {
  return build(MessageType::kCaptureRaw, out, [&](ByteWriter& w) { w.put(m.projectorsMask); });
}

ProtocolResult<std::span<const std::byte>> encode(const ConfigMessage& m,
                                                  std::span<std::byte> out) {
  return build(MessageType::kConfig, out, [&](ByteWriter& w) { w.putString32(m.json); });
}

ProtocolResult<std::span<const std::byte>> encode(const SetConfig& m, std::span<std::byte> out) {
  return build(MessageType::kSetConfig, out, [&](ByteWriter& w) {
    w.put(static_cast<std::uint8_t>(m.mode));
    w.putString32(m.json);
  });
}

ProtocolResult<std::span<const std::byte>> encode(const TurntableState& m,
                                                  std::span<std::byte> out) {
  return build(MessageType::kTurntable, out, [&](ByteWriter& w) {
    w.put(static_cast<std::uint8_t>(m.present ? 1 : 0));
    w.put(m.stepsPerTurn);
    w.put(static_cast<std::uint64_t>(m.position));
    w.put(static_cast<std::uint64_t>(m.angleUdeg));
    w.put(static_cast<std::uint64_t>(m.settledNs));
  });
}

ProtocolResult<std::span<const std::byte>> encode(const TurnTurntable& m,
                                                  std::span<std::byte> out) {
  return build(MessageType::kTurnTurntable, out, [&](ByteWriter& w) {
    w.put(static_cast<std::uint8_t>(m.mode));
    w.put(static_cast<std::uint64_t>(m.angleUdeg));
  });
}

ProtocolResult<std::span<const std::byte>> encodeRawFrame(RawFrameHeader header,
                                                          algo::ConstRgbView image,
                                                          std::span<std::byte> out) {
  if (image.width() < 1 || image.height() < 1 || image.width() > 0xFFFF ||
      image.height() > 0xFFFF) {
    return protocolFail(ProtocolErrc::kMalformed, "raw frame: image size outside 1..65535");
  }
  if (header.rows == 0 || header.firstRow + header.rows > image.height()) {
    return protocolFail(ProtocolErrc::kMalformed, "raw frame: band outside the image");
  }
  header.width = static_cast<std::uint16_t>(image.width());
  header.height = static_cast<std::uint16_t>(image.height());
  return build(MessageType::kRawFrame, out, [&](ByteWriter& w) {
    w.put(header.camera);
    w.put(header.projectorsMask);
    w.put(header.width);
    w.put(header.height);
    w.put(header.firstRow);
    w.put(header.rows);
    w.put(header.capture);
    w.put(static_cast<std::uint64_t>(header.captureTimestampNs));
    for (int y = header.firstRow; y < header.firstRow + header.rows; ++y) {
      w.putBytes(std::as_bytes(image.row(y)));
    }
  });
}

ProtocolResult<std::span<const std::byte>> encodeEmpty(MessageType type, std::span<std::byte> out) {
  return build(type, out, [](ByteWriter&) {});
}

ProtocolResult<std::span<const std::byte>> encodeRangeFrame(RangeFrameHeader header,
                                                            algo::ConstDepthPlane depth,
                                                            std::span<std::byte> out) {
  return encodeFrame(header, depth, nullptr, out);
}

ProtocolResult<std::span<const std::byte>> encodeRangeFrame(
    RangeFrameHeader header, algo::ConstDepthPlane depth,
    algo::ImageView<const std::uint8_t> confidence, std::span<std::byte> out) {
  return encodeFrame(header, depth, &confidence, out);
}

ProtocolResult<Hello> decodeHello(std::span<const std::byte> payload) {
  ByteReader in(payload);
  Hello m{in.getString16()};
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  return m;
}

ProtocolResult<Capabilities> decodeCapabilities(std::span<const std::byte> payload) {
  ByteReader in(payload);
  Capabilities m;
  m.board = in.getString16();
  m.firmwareVersion = in.getString16();
  m.halBackend = in.getString16();
  m.depthUnitNm = in.get<std::uint32_t>();
  m.cameras = in.get<std::uint8_t>();
  m.projectors = in.get<std::uint8_t>();
  m.width = in.get<std::uint16_t>();
  m.height = in.get<std::uint16_t>();
  m.fps = in.get<std::uint16_t>();
  m.compressionsMask = in.get<std::uint8_t>();
  m.rigJson = in.getString32();
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  if (m.depthUnitNm == 0) {
    return protocolFail(ProtocolErrc::kMalformed, "capabilities: depth unit is zero");
  }
  if ((m.compressionsMask & ~kKnownCompressions) != 0) {
    m.compressionsMask &= kKnownCompressions;  // a newer device: ignore what we cannot read
  }
  return m;
}

ProtocolResult<StartStream> decodeStartStream(std::span<const std::byte> payload) {
  ByteReader in(payload);
  const auto compression = in.get<std::uint8_t>();
  // The options byte is optional: a host that asks for nothing sends the compression only.
  const auto options = in.atEnd() ? std::uint8_t{0} : in.get<std::uint8_t>();
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  if (!validCompression(compression)) {
    return protocolFail(ProtocolErrc::kMalformed, "start-stream: unknown compression");
  }
  if ((options & ~kOptionConfidence) != 0) {
    return protocolFail(ProtocolErrc::kMalformed, "start-stream: unknown options");
  }
  return StartStream{.compression = static_cast<Compression>(compression),
                     .confidence = (options & kOptionConfidence) != 0};
}

ProtocolResult<Statistics> decodeStatistics(std::span<const std::byte> payload) {
  ByteReader in(payload);
  Statistics m;
  m.uptimeMs = in.get<std::uint64_t>();
  m.framesCaptured = in.get<std::uint64_t>();
  m.framesDecoded = in.get<std::uint64_t>();
  m.framesSent = in.get<std::uint64_t>();
  m.framesDropped = in.get<std::uint64_t>();
  m.captureErrors = in.get<std::uint64_t>();
  m.protocolErrors = in.get<std::uint64_t>();
  m.decodeTimeUsLast = in.get<std::uint32_t>();
  m.decodeTimeUsMean = in.get<std::uint32_t>();
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  return m;
}

ProtocolResult<ErrorMessage> decodeError(std::span<const std::byte> payload) {
  ByteReader in(payload);
  ErrorMessage m;
  m.code = static_cast<ErrorCode>(in.get<std::uint16_t>());
  m.text = in.getString16();
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  return m;
}

ProtocolResult<void> decodeEmpty(std::span<const std::byte> payload) {
  if (!payload.empty()) {
    return protocolFail(ProtocolErrc::kMalformed, "payload of a message that has none");
  }
  return {};
}

ProtocolResult<CaptureRaw> decodeCaptureRaw(std::span<const std::byte> payload) {
  ByteReader in(payload);
  CaptureRaw m{in.get<std::uint32_t>()};
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  return m;
}

ProtocolResult<TurntableState> decodeTurntable(std::span<const std::byte> payload) {
  ByteReader in(payload);
  const auto present = in.get<std::uint8_t>();
  TurntableState m;
  m.present = present == 1;
  m.stepsPerTurn = in.get<std::uint32_t>();
  m.position = static_cast<std::int64_t>(in.get<std::uint64_t>());
  m.angleUdeg = static_cast<std::int64_t>(in.get<std::uint64_t>());
  m.settledNs = static_cast<std::int64_t>(in.get<std::uint64_t>());
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  if (present > 1) {
    return protocolFail(ProtocolErrc::kMalformed, "turntable: present is neither 0 nor 1");
  }
  if (m.present && m.stepsPerTurn == 0) {
    return protocolFail(ProtocolErrc::kMalformed, "turntable: a turntable of 0 steps per turn");
  }
  return m;
}

ProtocolResult<TurnTurntable> decodeTurnTurntable(std::span<const std::byte> payload) {
  ByteReader in(payload);
  const auto mode = in.get<std::uint8_t>();
  const TurnTurntable m{static_cast<TurnMode>(mode),
                        static_cast<std::int64_t>(in.get<std::uint64_t>())};
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  if (mode > static_cast<std::uint8_t>(TurnMode::kAbsolute)) {
    return protocolFail(ProtocolErrc::kMalformed, "turn-turntable: unknown mode");
  }
  return m;
}

ProtocolResult<ConfigMessage> decodeConfig(std::span<const std::byte> payload) {
  ByteReader in(payload);
  const ConfigMessage m{in.getString32()};
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  return m;
}

ProtocolResult<SetConfig> decodeSetConfig(std::span<const std::byte> payload) {
  ByteReader in(payload);
  const auto mode = in.get<std::uint8_t>();
  const SetConfig m{static_cast<SetConfigMode>(mode), in.getString32()};
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  if (mode > static_cast<std::uint8_t>(SetConfigMode::kReset)) {
    return protocolFail(ProtocolErrc::kMalformed, "set-config: unknown mode");
  }
  return m;
}

ProtocolResult<RawFrameView> decodeRawFrame(std::span<const std::byte> payload) {
  ByteReader in(payload);
  RawFrameView m;
  m.header.camera = in.get<std::uint8_t>();
  m.header.projectorsMask = in.get<std::uint32_t>();
  m.header.width = in.get<std::uint16_t>();
  m.header.height = in.get<std::uint16_t>();
  m.header.firstRow = in.get<std::uint16_t>();
  m.header.rows = in.get<std::uint16_t>();
  m.header.capture = in.get<std::uint64_t>();
  m.header.captureTimestampNs = static_cast<std::int64_t>(in.get<std::uint64_t>());
  m.pixels = in.rest();
  if (!in.ok()) {
    return protocolFail(ProtocolErrc::kMalformed, "raw frame is shorter than its header");
  }
  const RawFrameHeader& h = m.header;
  if (h.width == 0 || h.height == 0 || h.rows == 0) {
    return protocolFail(ProtocolErrc::kMalformed, "raw frame: zero size or zero rows");
  }
  if (std::size_t{h.firstRow} + h.rows > h.height) {
    return protocolFail(ProtocolErrc::kMalformed, "raw frame: rows run past the frame's height");
  }
  if (m.pixels.size() != 3 * std::size_t{h.width} * h.rows) {
    return protocolFail(ProtocolErrc::kMalformed,
                        "raw frame: pixel bytes do not match rows x width x 3");
  }
  return m;
}

ProtocolResult<RangeFrameView> decodeRangeFrame(std::span<const std::byte> payload,
                                                MessageType type) {
  if (type != MessageType::kRangeFrame && type != MessageType::kRangeFrameConfidence) {
    return protocolFail(ProtocolErrc::kMalformed, "not a range frame message");
  }
  ByteReader in(payload);
  RangeFrameView m;
  m.header.camera = in.get<std::uint8_t>();
  const auto compression = in.get<std::uint8_t>();
  m.header.width = in.get<std::uint16_t>();
  m.header.height = in.get<std::uint16_t>();
  m.header.frame = in.get<std::uint64_t>();
  m.header.captureTimestampNs = static_cast<std::int64_t>(in.get<std::uint64_t>());
  m.header.sentTimestampNs = static_cast<std::int64_t>(in.get<std::uint64_t>());
  m.header.depthUnitNm = in.get<std::uint32_t>();
  m.header.decodeTimeUs = in.get<std::uint32_t>();
  m.hasConfidence = type == MessageType::kRangeFrameConfidence;
  const std::uint32_t depthBytes = m.hasConfidence ? in.get<std::uint32_t>() : 0;
  if (!in.ok()) {
    return protocolFail(ProtocolErrc::kMalformed, "range frame is shorter than its header");
  }
  if (m.hasConfidence) {
    m.depth = in.getBytes(depthBytes);
    if (!in.ok()) {
      return protocolFail(ProtocolErrc::kMalformed,
                          "range frame: depth size runs past the end of the payload");
    }
    m.confidence = in.rest();
  } else {
    m.depth = in.rest();
  }
  if (!validCompression(compression)) {
    return protocolFail(ProtocolErrc::kMalformed, "range frame: unknown compression");
  }
  m.header.compression = static_cast<Compression>(compression);
  if (m.header.width == 0 || m.header.height == 0 || m.header.depthUnitNm == 0) {
    return protocolFail(ProtocolErrc::kMalformed, "range frame: zero size or depth unit");
  }
  const std::size_t rawBytes = 2 * std::size_t{m.header.width} * m.header.height;
  if (m.header.compression == Compression::kNone && m.depth.size() != rawBytes) {
    return protocolFail(ProtocolErrc::kMalformed,
                        "range frame: raw depth size does not match width x height");
  }
  if (m.hasConfidence && m.header.compression == Compression::kNone &&
      m.confidence.size() != rawBytes / 2) {
    return protocolFail(ProtocolErrc::kMalformed,
                        "range frame: raw confidence plane size does not match width x height");
  }
  return m;
}

ProtocolResult<void> decodeRangeDepth(const RangeFrameView& frame, std::span<std::uint16_t> out) {
  if (out.size() != std::size_t{frame.header.width} * frame.header.height) {
    return protocolFail(ProtocolErrc::kBufferTooSmall, "depth buffer is not width x height");
  }
  if (frame.header.compression == Compression::kRvl) {
    return rvlDecode(frame.depth, out);
  }
  ByteReader in(frame.depth);
  for (std::uint16_t& value : out) {
    value = in.get<std::uint16_t>();
  }
  return finished(in);
}

ProtocolResult<void> decodeRangeConfidence(const RangeFrameView& frame,
                                           std::span<std::uint8_t> out) {
  if (!frame.hasConfidence) {
    return protocolFail(ProtocolErrc::kMalformed, "range frame has no confidence plane");
  }
  if (out.size() != std::size_t{frame.header.width} * frame.header.height) {
    return protocolFail(ProtocolErrc::kBufferTooSmall, "confidence buffer is not width x height");
  }
  if (frame.header.compression == Compression::kRvl) {
    return rvlDecode(frame.confidence, out);
  }
  ByteReader in(frame.confidence);
  for (std::uint8_t& value : out) {
    value = in.get<std::uint8_t>();
  }
  return finished(in);
}

}  // namespace smx::protocol
