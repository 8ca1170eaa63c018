#include "smx/protocol/update_messages.hpp"

#include "payload.hpp"
#include "smx/protocol/byte_io.hpp"

namespace smx::protocol {
namespace {

using detail::build;

template <class T>
ProtocolResult<T> finished(const ByteReader& in, const T& value) {
  if (auto whole = detail::finished(in); !whole) {
    return std::unexpected(whole.error());
  }
  return value;
}

}  // namespace

ProtocolResult<std::span<const std::byte>> encode(const FlashBegin& m, std::span<std::byte> out) {
  return build(MessageType::kFlashBegin, out, [&](ByteWriter& w) { w.put(m.size); });
}

ProtocolResult<std::span<const std::byte>> encode(const FlashData& m, std::span<std::byte> out) {
  return build(MessageType::kFlashData, out, [&](ByteWriter& w) { w.putBytes(m.bytes); });
}

ProtocolResult<std::span<const std::byte>> encode(const FlashProgress& m,
                                                  std::span<std::byte> out) {
  return build(MessageType::kFlashProgress, out, [&](ByteWriter& w) {
    w.put(static_cast<std::uint8_t>(m.step));
    w.put(m.bytes);
    w.putString16(m.text);
  });
}

ProtocolResult<std::span<const std::byte>> encode(const UpdateStatus& m, std::span<std::byte> out) {
  return build(MessageType::kUpdateStatus, out, [&](ByteWriter& w) {
    w.put(static_cast<std::uint8_t>(m.outcome));
    w.putString16(m.runningSlot);
    w.putString16(m.runningVersion);
    w.putString16(m.updateVersion);
    w.putString16(m.reason);
  });
}

ProtocolResult<FlashBegin> decodeFlashBegin(std::span<const std::byte> payload) {
  ByteReader in(payload);
  const FlashBegin m{in.get<std::uint64_t>()};
  return finished(in, m);
}

ProtocolResult<FlashData> decodeFlashData(std::span<const std::byte> payload) {
  if (payload.empty() || payload.size() > kFlashChunkBytes) {
    return protocolFail(ProtocolErrc::kMalformed, "flash-data: a chunk of 1 to 32768 bytes");
  }
  return FlashData{payload};
}

ProtocolResult<FlashProgress> decodeFlashProgress(std::span<const std::byte> payload) {
  ByteReader in(payload);
  const auto step = in.get<std::uint8_t>();
  const auto bytes = in.get<std::uint64_t>();
  const FlashProgress m{static_cast<FlashStep>(step), bytes, in.getString16()};
  if (step < 1 || step > kLastFlashStep) {
    return protocolFail(ProtocolErrc::kMalformed, "flash-progress: unknown step");
  }
  return finished(in, m);
}

ProtocolResult<UpdateStatus> decodeUpdateStatus(std::span<const std::byte> payload) {
  ByteReader in(payload);
  const auto outcome = in.get<std::uint8_t>();
  UpdateStatus m;
  m.outcome = static_cast<UpdateOutcomeCode>(outcome);
  m.runningSlot = in.getString16();
  m.runningVersion = in.getString16();
  m.updateVersion = in.getString16();
  m.reason = in.getString16();
  if (outcome > static_cast<std::uint8_t>(UpdateOutcomeCode::kRolledBack)) {
    return protocolFail(ProtocolErrc::kMalformed, "update-status: unknown outcome");
  }
  return finished(in, m);
}

}  // namespace smx::protocol
