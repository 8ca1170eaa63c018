#pragma once

#include <span>

#include "smx/protocol/byte_io.hpp"
#include "smx/protocol/wire.hpp"

// What every message codec of the library shares: a payload written in place behind its header,
// and a payload read to its exact end.
namespace smx::protocol::detail {

// Runs `writePayload` on the payload area of `out` and seals the message.
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

// The fields were all there and nothing follows them.
inline ProtocolResult<void> finished(const ByteReader& in) {
  if (!in.ok()) {
    return protocolFail(ProtocolErrc::kMalformed, "payload is shorter than its fields");
  }
  if (!in.atEnd()) {
    return protocolFail(ProtocolErrc::kMalformed, "payload has bytes after its fields");
  }
  return {};
}

}  // namespace smx::protocol::detail
