#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "smx/protocol/wire.hpp"

// The messages that open the owner's channel (docs/security.md): the session handshake
// (secure-hello, secure-accept) and pairing (pair-begin … pair-done). They travel in the clear,
// framed like every other message; everything after secure-accept is encrypted records.
namespace smx::protocol {

inline constexpr std::size_t kKeyBytes = 32;
using Key32 = std::array<std::byte, kKeyBytes>;

// secure-hello (host → device) and secure-accept (device → host) carry the same fields.
struct SecureHello {
  Key32 ephemeral;  // X25519, fresh for this connection
  Key32 identity;   // X25519, the sender's long-term key
};

struct PairRequest {
  Key32 element;   // ristretto255, derived from the code and a fresh secret
  Key32 identity;  // the host's long-term X25519 key
};

struct PairChallenge {
  Key32 element;
  Key32 identity;  // the device's long-term X25519 key
  Key32 proof;     // the device knows the code (a MAC over the transcript)
};

struct PairProof {
  Key32 proof;
};

struct PairReady {
  std::uint8_t attemptsLeft = 0;
  std::uint16_t secondsLeft = 0;
  std::uint8_t digits = 0;
};

// `type` is kSecureHello or kSecureAccept.
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encodeSecureHello(
    MessageType type, const SecureHello& m, std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const PairRequest& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const PairChallenge& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const PairProof& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const PairReady& m,
                                                                std::span<std::byte> out);

[[nodiscard]] ProtocolResult<SecureHello> decodeSecureHello(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<PairRequest> decodePairRequest(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<PairChallenge> decodePairChallenge(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<PairProof> decodePairProof(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<PairReady> decodePairReady(std::span<const std::byte> payload);

}  // namespace smx::protocol
