#pragma once

#include <cstddef>
#include <cstdint>
#include <expected>
#include <span>
#include <string>
#include <vector>

#include "smx/protocol/messages.hpp"

// A range-frame message from the device as the host keeps it. The frame's header comes from the
// network, so its camera and size are checked against what the device announced before the
// depth (and the confidence) is allocated.
namespace smx::host {

struct ReceivedFrame {
  protocol::RangeFrameHeader header;
  std::vector<std::uint16_t> depth;  // width × height, row by row
  // width × height when the host asked for it (a kRangeFrameConfidence message), else empty
  std::vector<std::uint8_t> confidence;
  std::size_t wireBytes = 0;    // the whole message
  std::int64_t receivedNs = 0;  // host CLOCK_MONOTONIC
};

// What the device's capabilities announced: every range frame is of one of its cameras and of
// their common size.
struct AnnouncedFrames {
  int cameras = 0;
  int width = 0;
  int height = 0;
};

// The range frame of a message payload (without the message header) of `type` kRangeFrame or
// kRangeFrameConfidence, received at receivedNs. A camera index outside the announced cameras, a
// size other than the announced one, or more pixels than an uncompressed frame can carry
// (protocol::kMaxPayloadBytes / 2, or / 3 with confidence) is an error naming both, found before
// anything is allocated; so is a payload that does not decode (naming the plane).
[[nodiscard]] std::expected<ReceivedFrame, std::string> receiveRangeFrame(
    std::span<const std::byte> payload, const AnnouncedFrames& announced, std::int64_t receivedNs,
    protocol::MessageType type = protocol::MessageType::kRangeFrame);

}  // namespace smx::host
