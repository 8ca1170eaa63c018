#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <span>

// The framing of every message on the link (docs/protocol.md): a 16-byte header, then the payload.
//
//   offset  size  field
//        0     4  magic "SMXP"
//        4     1  protocol version (kProtocolVersion)
//        5     1  message type (MessageType)
//        6     2  reserved, 0
//        8     4  payload length in bytes (at most the receiver's limit)
//       12     4  CRC-32 of bytes 0..11 and the payload
//
// All integers little-endian. Per frame nothing here allocates or throws.
namespace smx::protocol {

inline constexpr std::array<std::byte, 4> kMagic = {std::byte{'S'}, std::byte{'M'}, std::byte{'X'},
                                                    std::byte{'P'}};
inline constexpr std::uint8_t kProtocolVersion = 1;
inline constexpr std::size_t kHeaderBytes = 16;
inline constexpr std::uint16_t kDefaultPort = 5555;
// The largest payload either side sends: a 1280x960 range frame uncompressed, with room.
// Raw frames come in bands of rows well below it (messages.hpp, kRawBandPixelBytes).
inline constexpr std::size_t kMaxPayloadBytes = 4U << 20U;

enum class MessageType : std::uint8_t {
  kHello = 1,          // host → device: who connects
  kCapabilities = 2,   // device → host: board, firmware, rig (answer to hello)
  kStartStream = 3,    // host → device
  kStopStream = 4,     // host → device
  kRangeFrame = 5,     // device → host: one camera's merged range image
  kGetStatistics = 6,  // host → device
  kStatistics = 7,     // device → host: counters (answer to get-statistics, and at stream stop)
  kError = 8,          // device → host: a request was refused, with the reason
  // device → host, only to a host that asked for it: a range frame with its confidence plane
  kRangeFrameConfidence = 9,
  kCaptureRaw = 10,  // host → device: one raw frame per camera with the given projectors on
  kRawFrame = 11,    // device → host: a band of rows of one camera's raw frame (RGB8)
  kGetConfig = 12,   // host → device: the settings the device runs with
  kConfig = 13,      // device → host: its settings (answer to get-config and set-config)
  kSetConfig = 14,   // host → device: change settings (stored, then the device restarts)
  // The firmware update (update_messages.hpp).
  kFlashBegin = 15,       // host → device: a firmware bundle of this size follows
  kFlashData = 16,        // host → device: the bundle's next bytes
  kFlashEnd = 17,         // host → device: the bundle is whole: verify and install it
  kFlashProgress = 18,    // device → host: a step of the installation
  kGetUpdateStatus = 19,  // host → device: the last update's outcome
  kUpdateStatus = 20,     // device → host: its answer
  // The owner's channel (docs/security.md), sent in the clear before encryption starts.
  kSecureHello = 21,    // host → device: ephemeral and static key of a paired host
  kSecureAccept = 22,   // device → host: ephemeral and static key of the device
  kPairRequest = 23,    // host → device: its code-derived element and static key
  kPairChallenge = 24,  // device → host: its element, static key and proof of the code
  kPairProof = 25,      // host → device: its proof of the code
  kPairDone = 26,       // device → host: the host's key is stored
  kPairBegin = 27,      // host → device: open a pairing code (printed on the device's console)
  kPairReady = 28,      // device → host: a code is open, its attempts and seconds left
  // The turntable (messages.hpp).
  kGetTurntable = 29,   // host → device: the turntable's state
  kTurntable = 30,      // device → host: its state (answer to get- and turn-turntable)
  kTurnTurntable = 31,  // host → device: turn it, answered once it has settled
};

[[nodiscard]] bool isKnown(MessageType type);
[[nodiscard]] const char* toString(MessageType type);

// What was wrong with bytes received; the message is static, so reporting one never allocates.
enum class ProtocolErrc : std::uint8_t {
  kBadMagic,            // bytes that are not the start of a message (skipped to the next magic)
  kUnsupportedVersion,  // a message of another protocol version
  kUnknownType,
  kOversized,  // a payload length above the receiver's limit
  kBadCrc,
  kMalformed,       // a payload that does not hold what its type says (truncated, trailing bytes,
                    // values out of range)
  kBufferTooSmall,  // an encoder's output buffer cannot hold the message
};

struct ProtocolError {
  ProtocolErrc code;
  const char* message;
};

template <class T>
using ProtocolResult = std::expected<T, ProtocolError>;

[[nodiscard]] inline std::unexpected<ProtocolError> protocolFail(ProtocolErrc code,
                                                                 const char* message) {
  return std::unexpected(ProtocolError{code, message});
}

// One received message: its type and a view of its payload (valid until the parser moves on).
struct Message {
  MessageType type;
  std::span<const std::byte> payload;
};

// Writes the header for `payload` (already in place right after the header in `message`) and
// returns the whole message. `message` must hold kHeaderBytes + payload bytes.
[[nodiscard]] ProtocolResult<std::span<const std::byte>> sealMessage(std::span<std::byte> message,
                                                                     MessageType type,
                                                                     std::size_t payloadBytes);

}  // namespace smx::protocol
