// The device's side of the owner's channel: handshake, pairing, then records over the board link.
#include "smx/device/secure_link.hpp"

#include <cstdio>
#include <cstring>

#include "smx/protocol/messages.hpp"
#include "smx/protocol/secure_keys.hpp"
#include "smx/protocol/secure_messages.hpp"

namespace smx::device {

namespace {

using protocol::MessageType;

constexpr std::int64_t kPollNs = 50'000'000;
constexpr const char* kNotPaired =
    "not paired: this device serves its paired hosts only; run stripemux pair --device HOST";

}  // namespace

SecureLink::SecureLink(hal::Link& inner, Owners& owners, hal::Clock& clock)
    : inner_(inner), owners_(owners), clock_(clock), handshakeParser_(kHandshakeBytes) {}

hal::HalResult<void> SecureLink::acceptClient(std::int64_t timeoutNs) {
  if (auto accepted = inner_.acceptClient(timeoutNs); !accepted) {
    return accepted;
  }
  const std::int64_t deadline = clock_.nowNs() + kHandshakeNs;
  const auto type = readHandshake(deadline);
  if (type == MessageType::kSecureHello && openSession(deadline)) {
    return {};
  }
  if (type == MessageType::kPairBegin) {
    servePairBegin(deadline);
  } else if (type == MessageType::kPairRequest) {
    servePairRequest(deadline);
  }
  disconnect();
  return hal::halFail(hal::HalErrc::kTimeout, "no paired host connected");
}

std::optional<MessageType> SecureLink::readHandshake(std::int64_t deadlineNs) {
  std::array<std::byte, protocol::kHeaderBytes> header{};
  if (!readExact(header, deadlineNs)) {
    return std::nullopt;
  }
  const auto type = static_cast<MessageType>(header[5]);
  std::size_t length = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    length |= std::to_integer<std::size_t>(header[8 + i]) << (8 * i);
  }
  const bool handshake = type == MessageType::kSecureHello || type == MessageType::kPairBegin ||
                         type == MessageType::kPairRequest || type == MessageType::kPairProof;
  // Anything else (a hello of a host that never paired) is refused before its payload is read.
  if (!handshake || length > handshake_.size() - header.size()) {
    refuse(protocol::ErrorCode::kNotPaired, kNotPaired, deadlineNs);
    return std::nullopt;
  }
  std::memcpy(handshake_.data(), header.data(), header.size());
  if (!readExact(std::span(handshake_).subspan(header.size(), length), deadlineNs)) {
    return std::nullopt;
  }
  handshakeParser_.reset();
  (void)handshakeParser_.feed(std::span(handshake_).first(header.size() + length));
  const auto next = handshakeParser_.next();
  if (!next) {
    refuse(protocol::ErrorCode::kBadRequest, next.error().message, deadlineNs);
    return std::nullopt;
  }
  const std::optional<protocol::Message>& parsed = *next;
  if (!parsed.has_value()) {
    refuse(protocol::ErrorCode::kBadRequest, "a malformed handshake message", deadlineNs);
    return std::nullopt;
  }
  const protocol::Message& message = *parsed;
  hsPayloadSize_ = message.payload.size();
  std::memcpy(hsPayload_.data(), message.payload.data(), hsPayloadSize_);
  return message.type;
}

bool SecureLink::readExact(std::span<std::byte> out, std::int64_t deadlineNs) {
  std::size_t have = 0;
  while (have < out.size()) {
    const std::int64_t left = deadlineNs - clock_.nowNs();
    if (left <= 0) {
      return false;
    }
    const auto got = inner_.receiveSome(out.subspan(have), std::min(left, kPollNs));
    if (!got) {
      return false;
    }
    have += *got;
  }
  return true;
}

bool SecureLink::writeAll(std::span<const std::byte> bytes, std::int64_t deadlineNs) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    if (clock_.nowNs() > deadlineNs) {
      return false;
    }
    const auto n = inner_.sendSome(bytes.subspan(done));
    if (!n) {
      return false;
    }
    done += *n;
    if (*n == 0) {
      (void)inner_.waitForIo(true, kPollNs);
    }
  }
  return true;
}

void SecureLink::refuse(protocol::ErrorCode code, std::string_view reason,
                        std::int64_t deadlineNs) {
  std::array<std::byte, 512> out{};
  if (const auto error = protocol::encode(protocol::ErrorMessage{code, reason}, out)) {
    (void)writeAll(*error, deadlineNs);
  }
  disconnect();
}

bool SecureLink::openSession(std::int64_t deadlineNs) {
  const auto hello = protocol::decodeSecureHello(std::span(hsPayload_).first(hsPayloadSize_));
  if (!hello) {
    refuse(protocol::ErrorCode::kBadRequest, hello.error().message, deadlineNs);
    return false;
  }
  if (!owners_.isPaired(hello->identity)) {
    refuse(protocol::ErrorCode::kNotPaired, kNotPaired, deadlineNs);
    return false;
  }
  const protocol::KeyPair ephemeral = protocol::generateKeyPair();
  const auto keys =
      protocol::deriveSessionKeys(protocol::Role::kDevice, ephemeral, owners_.identity(), *hello);
  if (!keys) {
    refuse(protocol::ErrorCode::kBadRequest, "secure-hello: an invalid key", deadlineNs);
    return false;
  }
  std::array<std::byte, 128> out{};
  const auto accept = protocol::encodeSecureHello(
      MessageType::kSecureAccept, {ephemeral.publicKey, owners_.identity().publicKey}, out);
  if (!accept || !writeAll(*accept, deadlineNs)) {
    return false;
  }
  channel_.start(*keys, protocol::Role::kDevice);
  if (!writeAll(channel_.pending(), deadlineNs)) {
    return false;
  }
  channel_.sent(channel_.pending().size());
  // The host's key confirmation, before any of its records is handed up.
  while (!channel_.confirmed()) {
    const auto space = channel_.writable();
    if (!space.empty() && !readExact(space, deadlineNs)) {
      return false;
    }
    channel_.commit(space.size());
    if (!channel_.read({})) {
      return false;
    }
  }
  ready_ = true;
  return true;
}

void SecureLink::announcePairing() {
  if (owners_.pairingOpen()) {
    printNewCode(clock_.nowNs());
  }
}

void SecureLink::printNewCode(std::int64_t nowNs) {
  if (const auto code = code_.open(nowNs)) {
    std::printf("pairing code: %s (valid %lld s, %d attempts; stripemux pair --device HOST)\n",
                code->c_str(),
                static_cast<long long>(protocol::PairingCode::kLifetimeNs / 1'000'000'000),
                protocol::PairingCode::kAttempts);
    std::fflush(stdout);
  }
}

void SecureLink::servePairBegin(std::int64_t deadlineNs) {
  const std::int64_t now = clock_.nowNs();
  if (!owners_.pairingOpen()) {
    refuse(protocol::ErrorCode::kNotPaired,
           "pairing is closed: this device has paired hosts; restart stripemuxd with --pair, or "
           "add the host's key to the state directory's hosts/ (docs/security.md)",
           deadlineNs);
    return;
  }
  printNewCode(now);
  if (!code_.isOpen(now)) {
    refuse(protocol::ErrorCode::kBusy, "pairing: no new code yet; try again in 10 s", deadlineNs);
    return;
  }
  std::array<std::byte, 64> out{};
  const auto ready = protocol::encode(
      protocol::PairReady{static_cast<std::uint8_t>(code_.attemptsLeft()),
                          static_cast<std::uint16_t>(code_.secondsLeft(now)),
                          static_cast<std::uint8_t>(protocol::PairingCode::kDigits)},
      out);
  if (ready) {
    (void)writeAll(*ready, deadlineNs);
  }
}

void SecureLink::servePairRequest(std::int64_t deadlineNs) {
  const auto request = protocol::decodePairRequest(std::span(hsPayload_).first(hsPayloadSize_));
  if (!request) {
    refuse(protocol::ErrorCode::kBadRequest, request.error().message, deadlineNs);
    return;
  }
  const auto code = owners_.pairingOpen() ? code_.attempt(clock_.nowNs()) : std::nullopt;
  if (!code) {
    refuse(protocol::ErrorCode::kNotPaired,
           "pairing: no code is open; run stripemux pair again (it asks the device for one)",
           deadlineNs);
    return;
  }
  const protocol::PakeShare share = protocol::pakeStart(*code);
  const protocol::Key32& identity = owners_.identity().publicKey;
  const auto keys =
      protocol::pakeFinish(share, request->element, *request, share.element, identity);
  if (!keys) {
    refuse(protocol::ErrorCode::kBadRequest, "pair-request: an invalid element", deadlineNs);
    return;
  }
  std::array<std::byte, 256> out{};
  const auto challenge =
      protocol::encode(protocol::PairChallenge{share.element, identity, keys->deviceProof}, out);
  if (!challenge) {
    refuse(protocol::ErrorCode::kInternal, challenge.error().message, deadlineNs);
    return;
  }
  if (!writeAll(*challenge, deadlineNs) || readHandshake(deadlineNs) != MessageType::kPairProof) {
    return;
  }
  const auto proof = protocol::decodePairProof(std::span(hsPayload_).first(hsPayloadSize_));
  if (!proof || !protocol::sameProof(proof->proof, keys->hostProof)) {
    const int left = code_.attemptsLeft();
    std::printf("pairing: a wrong code (%d attempts left%s)\n", left,
                left == 0 ? "; a new code is printed when a host asks" : "");
    std::fflush(stdout);
    std::array<char, 96> reason{};
    std::snprintf(reason.data(), reason.size(), "pairing: wrong code, %d attempts left", left);
    refuse(protocol::ErrorCode::kNotPaired, reason.data(), deadlineNs);
    return;
  }
  const auto stored = owners_.addHost(request->identity);
  if (!stored) {
    refuse(protocol::ErrorCode::kInternal, "pairing: the device could not store the key",
           deadlineNs);
    std::printf("pairing: %s\n", stored.error().c_str());
    return;
  }
  code_.close();
  std::printf("paired with host %s (%s)\n", protocol::fingerprint(request->identity).c_str(),
              stored->c_str());
  std::fflush(stdout);
  if (const auto done = protocol::encodeEmpty(MessageType::kPairDone, out)) {
    (void)writeAll(*done, deadlineNs);
  }
}

hal::HalResult<std::size_t> SecureLink::sendSome(std::span<const std::byte> bytes) {
  if (!flush()) {
    disconnect();
    return hal::halFail(hal::HalErrc::kDisconnected, "the host went away");
  }
  if (!channel_.pending().empty()) {
    return 0;
  }
  const std::size_t taken = channel_.seal(bytes);
  if (!flush()) {
    disconnect();
    return hal::halFail(hal::HalErrc::kDisconnected, "the host went away");
  }
  return taken;
}

bool SecureLink::flush() {
  while (!channel_.pending().empty()) {
    const auto n = inner_.sendSome(channel_.pending());
    if (!n) {
      return false;
    }
    if (*n == 0) {
      return true;
    }
    channel_.sent(*n);
  }
  return true;
}

hal::HalResult<std::size_t> SecureLink::receiveSome(std::span<std::byte> bytes,
                                                    std::int64_t timeoutNs) {
  std::int64_t wait = timeoutNs;
  while (true) {
    const auto got = channel_.read(bytes);
    if (!got) {
      disconnect();  // tampered, replayed, reordered or cut: nothing more is believed
      return hal::halFail(hal::HalErrc::kDisconnected, got.error().message);
    }
    if (*got > 0) {
      return *got;
    }
    const auto space = channel_.writable();
    if (space.empty()) {
      continue;  // a whole unit waits: read() opens it
    }
    const auto received = inner_.receiveSome(space, wait);
    if (!received) {
      disconnect();
      return received;
    }
    if (*received == 0) {
      return 0;
    }
    channel_.commit(*received);
    wait = 0;
  }
}

hal::HalResult<void> SecureLink::waitForIo(bool wantWrite, std::int64_t timeoutNs) {
  if (!flush()) {
    return hal::halFail(hal::HalErrc::kDisconnected, "the host went away");
  }
  if (channel_.hasPlain()) {
    return {};
  }
  return inner_.waitForIo(wantWrite || !channel_.pending().empty(), timeoutNs);
}

void SecureLink::disconnect() {
  inner_.disconnect();
  channel_.reset();
  ready_ = false;
}

}  // namespace smx::device
