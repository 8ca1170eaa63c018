#include "smx/protocol/stream_parser.hpp"

#include <algorithm>
#include <cstring>

#include "smx/protocol/byte_io.hpp"
#include "smx/protocol/crc32.hpp"

namespace smx::protocol {

StreamParser::StreamParser(std::size_t maxPayloadBytes)
    : buffer_(kHeaderBytes + maxPayloadBytes), maxPayloadBytes_(maxPayloadBytes) {}

std::span<const std::byte> StreamParser::buffered() const {
  return std::span(buffer_).subspan(begin_, end_ - begin_);
}

std::span<std::byte> StreamParser::writable() {
  if (begin_ > 0) {
    const std::size_t kept = end_ - begin_;
    if (kept > 0) {
      std::memmove(buffer_.data(), buffer_.data() + begin_, kept);
    }
    begin_ = 0;
    end_ = kept;
  }
  return std::span(buffer_).subspan(end_);
}

void StreamParser::commit(std::size_t bytes) {
  end_ = std::min(end_ + bytes, buffer_.size());
}

std::size_t StreamParser::feed(std::span<const std::byte> bytes) {
  const std::span<std::byte> room = writable();
  const std::size_t count = std::min(room.size(), bytes.size());
  if (count > 0) {
    std::memcpy(room.data(), bytes.data(), count);
  }
  commit(count);
  return count;
}

void StreamParser::reset() {
  begin_ = 0;
  end_ = 0;
}

std::unexpected<ProtocolError> StreamParser::skipAfterError(ProtocolErrc code,
                                                            const char* message) {
  // Drop the first byte of the bad message, then everything up to the next possible magic.
  const std::span<const std::byte> rest = buffered().subspan(1);
  const auto found = std::search(rest.begin(), rest.end(), kMagic.begin(), kMagic.end());
  std::size_t skip = 1 + static_cast<std::size_t>(found - rest.begin());
  if (found == rest.end()) {
    // Keep a tail that may be the start of a magic split across reads.
    skip = 1 + rest.size() - std::min<std::size_t>(rest.size(), kMagic.size() - 1);
  }
  begin_ += skip;
  counters_.bytesSkipped += skip;
  ++counters_.errors;
  return std::unexpected(ProtocolError{code, message});
}

ProtocolResult<std::optional<Message>> StreamParser::next() {
  const std::span<const std::byte> bytes = buffered();
  const std::size_t magicBytes = std::min(bytes.size(), kMagic.size());
  if (!std::equal(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(magicBytes),
                  kMagic.begin())) {
    return skipAfterError(ProtocolErrc::kBadMagic, "bytes that do not start a message");
  }
  if (bytes.size() < kHeaderBytes) {
    return std::nullopt;
  }
  ByteReader header(bytes.first(kHeaderBytes));
  (void)header.getBytes(kMagic.size());
  const auto version = header.get<std::uint8_t>();
  const auto type = static_cast<MessageType>(header.get<std::uint8_t>());
  const auto reserved = header.get<std::uint16_t>();
  const auto length = header.get<std::uint32_t>();
  const auto crc = header.get<std::uint32_t>();
  if (version != kProtocolVersion) {
    return skipAfterError(ProtocolErrc::kUnsupportedVersion, "message of another protocol version");
  }
  if (!isKnown(type) || reserved != 0) {
    return skipAfterError(ProtocolErrc::kUnknownType, "message of an unknown type");
  }
  if (length > maxPayloadBytes_) {
    return skipAfterError(ProtocolErrc::kOversized, "message longer than this receiver accepts");
  }
  if (bytes.size() - kHeaderBytes < length) {
    return std::nullopt;
  }
  const std::span<const std::byte> payload = bytes.subspan(kHeaderBytes, length);
  if (crc32Update(crc32(bytes.first(12)), payload) != crc) {
    return skipAfterError(ProtocolErrc::kBadCrc, "message with a wrong CRC");
  }
  begin_ += kHeaderBytes + length;
  ++counters_.messages;
  return Message{type, payload};
}

}  // namespace smx::protocol
