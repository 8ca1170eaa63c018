#pragma once

#include <cstdint>
#include <optional>

#include "smx/device/owners.hpp"
#include "smx/hal/clock.hpp"
#include "smx/hal/link.hpp"
#include "smx/protocol/messages.hpp"
#include "smx/protocol/secure_pairing.hpp"
#include "smx/protocol/secure_session.hpp"
#include "smx/protocol/stream_parser.hpp"

// The board's link with the owner's channel (docs/security.md): after the inner link accepts a
// host, the host must open an encrypted session as a paired host, or pair, before connected()
// turns true; anything else gets the clear-text error `not paired` (code 5) and is disconnected
// before another byte is read. The Device above sees plaintext as before. Pairing codes are
// printed on stdout (the device's console), never sent. Buffers are allocated at construction:
// the session's records allocate nothing; a handshake reads the paired hosts' files.
namespace smx::device {

class SecureLink final : public hal::Link {
 public:
  // How long one handshake (or pairing exchange) may take before the host is dropped.
  static constexpr std::int64_t kHandshakeNs = 5'000'000'000;
  // The largest handshake message (pair-challenge: 16 + 96 bytes), with room.
  static constexpr std::size_t kHandshakeBytes = 256;

  SecureLink(hal::Link& inner, Owners& owners, hal::Clock& clock);
  // Opens and prints a pairing code now when pairing is open (at start, so that the owner sees
  // it before the host asks).
  void announcePairing();

  [[nodiscard]] hal::HalResult<void> acceptClient(std::int64_t timeoutNs) override;
  [[nodiscard]] bool connected() const override { return ready_ && inner_.connected(); }
  [[nodiscard]] hal::HalResult<std::size_t> sendSome(std::span<const std::byte> bytes) override;
  [[nodiscard]] hal::HalResult<std::size_t> receiveSome(std::span<std::byte> bytes,
                                                        std::int64_t timeoutNs) override;
  [[nodiscard]] hal::HalResult<void> waitForIo(bool wantWrite, std::int64_t timeoutNs) override;
  void disconnect() override;
  [[nodiscard]] std::uint16_t port() const override { return inner_.port(); }

 private:
  // The next clear-text handshake message (payload in hsPayload_), or nullopt when the host is
  // gone, too slow or sent something else (then answered and dropped).
  [[nodiscard]] std::optional<protocol::MessageType> readHandshake(std::int64_t deadlineNs);
  [[nodiscard]] bool readExact(std::span<std::byte> out, std::int64_t deadlineNs);
  [[nodiscard]] bool writeAll(std::span<const std::byte> bytes, std::int64_t deadlineNs);
  [[nodiscard]] bool flush();
  // Sends a clear-text error and drops the host.
  void refuse(protocol::ErrorCode code, std::string_view reason, std::int64_t deadlineNs);
  [[nodiscard]] bool openSession(std::int64_t deadlineNs);
  void printNewCode(std::int64_t nowNs);
  void servePairBegin(std::int64_t deadlineNs);
  void servePairRequest(std::int64_t deadlineNs);

  hal::Link& inner_;
  Owners& owners_;
  hal::Clock& clock_;
  protocol::SecureChannel channel_;
  protocol::PairingCode code_;
  protocol::StreamParser handshakeParser_;
  std::array<std::byte, kHandshakeBytes> handshake_{};
  std::array<std::byte, kHandshakeBytes> hsPayload_{};
  std::size_t hsPayloadSize_ = 0;
  bool ready_ = false;
};

}  // namespace smx::device
