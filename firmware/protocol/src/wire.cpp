#include "smx/protocol/wire.hpp"

#include <algorithm>

#include "smx/protocol/byte_io.hpp"
#include "smx/protocol/crc32.hpp"

namespace smx::protocol {

bool isKnown(MessageType type) {
  const auto value = static_cast<std::uint8_t>(type);
  return value >= static_cast<std::uint8_t>(MessageType::kHello) &&
         value <= static_cast<std::uint8_t>(MessageType::kTurnTurntable);
}

const char* toString(MessageType type) {
  switch (type) {
    case MessageType::kHello:
      return "hello";
    case MessageType::kCapabilities:
      return "capabilities";
    case MessageType::kStartStream:
      return "start-stream";
    case MessageType::kStopStream:
      return "stop-stream";
    case MessageType::kRangeFrame:
      return "range-frame";
    case MessageType::kGetStatistics:
      return "get-statistics";
    case MessageType::kStatistics:
      return "statistics";
    case MessageType::kError:
      return "error";
    case MessageType::kRangeFrameConfidence:
      return "range-frame-confidence";
    case MessageType::kCaptureRaw:
      return "capture-raw";
    case MessageType::kRawFrame:
      return "raw-frame";
    case MessageType::kGetConfig:
      return "get-config";
    case MessageType::kConfig:
      return "config";
    case MessageType::kSetConfig:
      return "set-config";
    case MessageType::kFlashBegin:
      return "flash-begin";
    case MessageType::kFlashData:
      return "flash-data";
    case MessageType::kFlashEnd:
      return "flash-end";
    case MessageType::kFlashProgress:
      return "flash-progress";
    case MessageType::kGetUpdateStatus:
      return "get-update-status";
    case MessageType::kUpdateStatus:
      return "update-status";
    case MessageType::kSecureHello:
      return "secure-hello";
    case MessageType::kSecureAccept:
      return "secure-accept";
    case MessageType::kPairRequest:
      return "pair-request";
    case MessageType::kPairChallenge:
      return "pair-challenge";
    case MessageType::kPairProof:
      return "pair-proof";
    case MessageType::kPairDone:
      return "pair-done";
    case MessageType::kPairBegin:
      return "pair-begin";
    case MessageType::kPairReady:
      return "pair-ready";
    case MessageType::kGetTurntable:
      return "get-turntable";
    case MessageType::kTurntable:
      return "turntable";
    case MessageType::kTurnTurntable:
      return "turn-turntable";
  }
  return "unknown";
}

ProtocolResult<std::span<const std::byte>> sealMessage(std::span<std::byte> message,
                                                       MessageType type, std::size_t payloadBytes) {
  if (payloadBytes > kMaxPayloadBytes || message.size() < kHeaderBytes ||
      message.size() - kHeaderBytes < payloadBytes) {
    return protocolFail(ProtocolErrc::kBufferTooSmall, "message does not fit its buffer");
  }
  ByteWriter header(message.first(kHeaderBytes));
  header.putBytes(kMagic);
  header.put(kProtocolVersion);
  header.put(static_cast<std::uint8_t>(type));
  header.put(std::uint16_t{0});
  header.put(static_cast<std::uint32_t>(payloadBytes));
  const std::uint32_t crc =
      crc32Update(crc32(message.first(12)), message.subspan(kHeaderBytes, payloadBytes));
  header.put(crc);
  return std::span<const std::byte>(message.first(kHeaderBytes + payloadBytes));
}

}  // namespace smx::protocol
