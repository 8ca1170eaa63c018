#include "smx/protocol/messages.hpp"

#include <algorithm>

#include "smx/protocol/byte_io.hpp"
#include "smx/protocol/rvl.hpp"

namespace smx::protocol {

namespace {

constexpr std::uint8_t kKnownCompressions = (1U << 0U) | (1U << 1U);

// Runs `writePayload` on the payload area and seals the message.
template <class WritePayload>
ProtocolResult<std::span<const std::byte>> build(MessageType type, std::span<std::byte> out,
                                                 WritePayload&& writePayload) {
  if (out.size() < kHeaderBytes) {
    return protocolFail(ProtocolErrc::kBufferTooSmall, "message does not fit its buffer");
  }
  ByteWriter payload(out.subspan(kHeaderBytes));
  writePayload(payload);
  if (!payload.ok()) {
    return protocolFail(ProtocolErrc::kBufferTooSmall, "message does not fit its buffer");
  }
  return sealMessage(out, type, payload.size());
}

ProtocolResult<void> finished(const ByteReader& in) {
  if (!in.ok()) {
    return protocolFail(ProtocolErrc::kMalformed, "payload is shorter than its fields");
  }
  if (!in.atEnd()) {
    return protocolFail(ProtocolErrc::kMalformed, "payload has bytes after its fields");
  }
  return {};
}

bool validCompression(std::uint8_t value) {
  return value <= 1;
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
  return build(MessageType::kStartStream, out,
               [&](ByteWriter& w) { w.put(static_cast<std::uint8_t>(m.compression)); });
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

ProtocolResult<std::span<const std::byte>> encodeEmpty(MessageType type, std::span<std::byte> out) {
  return build(type, out, [](ByteWriter&) {});
}

ProtocolResult<std::span<const std::byte>> encodeRangeFrame(RangeFrameHeader header,
                                                            algo::ConstDepthPlane depth,
                                                            std::span<std::byte> out) {
  header.width = static_cast<std::uint16_t>(depth.width());
  header.height = static_cast<std::uint16_t>(depth.height());
  const auto writeHeader = [&](ByteWriter& w) {
    w.put(header.camera);
    w.put(static_cast<std::uint8_t>(header.compression));
    w.put(header.width);
    w.put(header.height);
    w.put(header.frame);
    w.put(static_cast<std::uint64_t>(header.captureTimestampNs));
    w.put(static_cast<std::uint64_t>(header.sentTimestampNs));
    w.put(header.depthUnitNm);
    w.put(header.decodeTimeUs);
  };
  const auto writeRaw = [&](ByteWriter& w) {
    writeHeader(w);
    for (int y = 0; y < depth.height(); ++y) {
      for (const std::uint16_t value : depth.row(y)) {
        w.put(value);
      }
    }
  };
  if (depth.width() > 0xFFFF || depth.height() > 0xFFFF) {
    return protocolFail(ProtocolErrc::kBufferTooSmall, "range image is larger than 65535 px");
  }
  if (header.compression == Compression::kRvl) {
    auto rvl = build(MessageType::kRangeFrame, out, [&](ByteWriter& w) {
      writeHeader(w);
      const std::size_t rawBytes =
          2 * static_cast<std::size_t>(depth.width()) * static_cast<std::size_t>(depth.height());
      const std::span<std::byte> room = w.remaining();
      const auto packed = rvlEncode(depth, room.first(std::min(room.size(), rawBytes)));
      if (packed) {
        w.advance(*packed);
      } else {
        w.advance(room.size() + 1);  // marks the writer failed: fall back to raw below
      }
    });
    if (rvl) {
      return rvl;
    }
    header.compression = Compression::kNone;
  }
  return build(MessageType::kRangeFrame, out, writeRaw);
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
  if (auto ok = finished(in); !ok) {
    return std::unexpected(ok.error());
  }
  if (!validCompression(compression)) {
    return protocolFail(ProtocolErrc::kMalformed, "start-stream: unknown compression");
  }
  return StartStream{static_cast<Compression>(compression)};
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

ProtocolResult<RangeFrameView> decodeRangeFrame(std::span<const std::byte> payload) {
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
  m.depth = in.rest();
  if (!in.ok()) {
    return protocolFail(ProtocolErrc::kMalformed, "range frame is shorter than its header");
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

}  // namespace smx::protocol
