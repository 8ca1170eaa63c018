#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "smx/protocol/wire.hpp"

// The firmware upload (docs/protocol.md, messages 15–20): flash-begin with the bundle's size,
// flash-data chunks, flash-end; the device answers with flash-progress steps (the last one
// kRestarting) or an error (kUpdateRefused), then restarts into the new firmware.
namespace smx::protocol {

// A flash-data chunk's bytes at most: within the device's request buffer, which is sized for a
// set-config (64 KiB of settings), so that the upload costs the device no memory of its own.
inline constexpr std::size_t kFlashChunkBytes = std::size_t{32} * 1024;

struct FlashBegin {
  std::uint64_t size = 0;  // of the whole bundle
};

struct FlashData {
  std::span<const std::byte> bytes;  // 1 … kFlashChunkBytes
};

enum class FlashStep : std::uint8_t {
  kReceived = 1,     // the bundle is on the device's disk
  kVerified = 2,     // signature, board and version checked
  kSlotWritten = 3,  // extracted into the inactive slot and flushed
  kSwitched = 4,     // the slot is active and on trial
  kRestarting = 5,   // the last step: the device restarts into it
};
inline constexpr std::uint8_t kLastFlashStep = 5;

struct FlashProgress {
  FlashStep step = FlashStep::kReceived;
  std::uint64_t bytes = 0;  // of the bundle received
  std::string_view text;
};

enum class UpdateOutcomeCode : std::uint8_t { kNone = 0, kInstalled = 1, kRolledBack = 2 };

struct UpdateStatus {
  UpdateOutcomeCode outcome = UpdateOutcomeCode::kNone;
  std::string_view runningSlot;     // "a", "b", or "factory"
  std::string_view runningVersion;  // of the firmware that answers
  std::string_view updateVersion;   // of the last update ("" when none)
  std::string_view reason;          // why it was rolled back
};

[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const FlashBegin& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const FlashData& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const FlashProgress& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const UpdateStatus& m,
                                                                std::span<std::byte> out);

[[nodiscard]] ProtocolResult<FlashBegin> decodeFlashBegin(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<FlashData> decodeFlashData(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<FlashProgress> decodeFlashProgress(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<UpdateStatus> decodeUpdateStatus(std::span<const std::byte> payload);

}  // namespace smx::protocol
