#include "smx/protocol/secure_messages.hpp"

#include <algorithm>

#include "payload.hpp"
#include "smx/protocol/byte_io.hpp"

namespace smx::protocol {

namespace {

constexpr std::uint8_t kMaxAttempts = 3;
constexpr std::uint16_t kMaxSeconds = 3600;

using detail::build;
using detail::finished;

Key32 getKey(ByteReader& in) {
  Key32 key{};
  const auto bytes = in.getBytes(kKeyBytes);
  std::copy(bytes.begin(), bytes.end(), key.begin());
  return key;
}

}  // namespace

ProtocolResult<std::span<const std::byte>> encodeSecureHello(MessageType type, const SecureHello& m,
                                                             std::span<std::byte> out) {
  if (type != MessageType::kSecureHello && type != MessageType::kSecureAccept) {
    return protocolFail(ProtocolErrc::kMalformed, "not a secure-hello or secure-accept");
  }
  return build(type, out, [&](ByteWriter& w) {
    w.putBytes(m.ephemeral);
    w.putBytes(m.identity);
  });
}

ProtocolResult<std::span<const std::byte>> encode(const PairRequest& m, std::span<std::byte> out) {
  return build(MessageType::kPairRequest, out, [&](ByteWriter& w) {
    w.putBytes(m.element);
    w.putBytes(m.identity);
  });
}

ProtocolResult<std::span<const std::byte>> encode(const PairChallenge& m,
                                                  std::span<std::byte> out) {
  return build(MessageType::kPairChallenge, out, [&](ByteWriter& w) {
    w.putBytes(m.element);
    w.putBytes(m.identity);
    w.putBytes(m.proof);
  });
}

ProtocolResult<std::span<const std::byte>> encode(const PairProof& m, std::span<std::byte> out) {
  return build(MessageType::kPairProof, out, [&](ByteWriter& w) { w.putBytes(m.proof); });
}

ProtocolResult<std::span<const std::byte>> encode(const PairReady& m, std::span<std::byte> out) {
  return build(MessageType::kPairReady, out, [&](ByteWriter& w) {
    w.put(m.attemptsLeft);
    w.put(m.secondsLeft);
    w.put(m.digits);
  });
}

ProtocolResult<SecureHello> decodeSecureHello(std::span<const std::byte> payload) {
  ByteReader in(payload);
  SecureHello m{};
  m.ephemeral = getKey(in);
  m.identity = getKey(in);
  if (auto done = finished(in); !done) {
    return std::unexpected(done.error());
  }
  return m;
}

ProtocolResult<PairRequest> decodePairRequest(std::span<const std::byte> payload) {
  ByteReader in(payload);
  PairRequest m{};
  m.element = getKey(in);
  m.identity = getKey(in);
  if (auto done = finished(in); !done) {
    return std::unexpected(done.error());
  }
  return m;
}

ProtocolResult<PairChallenge> decodePairChallenge(std::span<const std::byte> payload) {
  ByteReader in(payload);
  PairChallenge m{};
  m.element = getKey(in);
  m.identity = getKey(in);
  m.proof = getKey(in);
  if (auto done = finished(in); !done) {
    return std::unexpected(done.error());
  }
  return m;
}

ProtocolResult<PairProof> decodePairProof(std::span<const std::byte> payload) {
  ByteReader in(payload);
  PairProof m{};
  m.proof = getKey(in);
  if (auto done = finished(in); !done) {
    return std::unexpected(done.error());
  }
  return m;
}

ProtocolResult<PairReady> decodePairReady(std::span<const std::byte> payload) {
  ByteReader in(payload);
  PairReady m{};
  m.attemptsLeft = in.get<std::uint8_t>();
  m.secondsLeft = in.get<std::uint16_t>();
  m.digits = in.get<std::uint8_t>();
  if (auto done = finished(in); !done) {
    return std::unexpected(done.error());
  }
  if (m.attemptsLeft > kMaxAttempts || m.secondsLeft > kMaxSeconds || m.digits < 6 ||
      m.digits > 8) {
    return protocolFail(ProtocolErrc::kMalformed, "pair-ready: a value out of range");
  }
  return m;
}

}  // namespace smx::protocol
