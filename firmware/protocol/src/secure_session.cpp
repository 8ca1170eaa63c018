#include "smx/protocol/secure_session.hpp"

#include <sodium.h>

#include <algorithm>
#include <cstring>

#include "sodium_ready.hpp"

namespace smx::protocol {

namespace {

static_assert(kRecordTagBytes == crypto_secretstream_xchacha20poly1305_ABYTES);
static_assert(kStreamHeaderBytes == crypto_secretstream_xchacha20poly1305_HEADERBYTES);
static_assert(kKeyBytes == crypto_secretstream_xchacha20poly1305_KEYBYTES);
static_assert(kKeyBytes == crypto_scalarmult_BYTES);

constexpr std::string_view kTranscriptLabel = "stripemux secure session 1";
constexpr std::string_view kConfirmLabel = "SMXK";
constexpr std::size_t kConfirmBytes = kConfirmLabel.size() + kKeyBytes;
constexpr std::size_t kRecordMaxBytes = kRecordPlainBytes + kRecordTagBytes;

auto* u8(std::byte* p) {
  return reinterpret_cast<unsigned char*>(p);
}
const auto* u8(const std::byte* p) {
  return reinterpret_cast<const unsigned char*>(p);
}

void hashUpdate(crypto_generichash_state& state, std::span<const std::byte> bytes) {
  crypto_generichash_update(&state, u8(bytes.data()), bytes.size());
}

}  // namespace

KeyPair generateKeyPair() {
  sodiumReady();
  KeyPair pair;
  crypto_kx_keypair(u8(pair.publicKey.data()), u8(pair.secretKey.data()));
  return pair;
}

Key32 publicKeyOf(const Key32& secretKey) {
  sodiumReady();
  Key32 key{};
  crypto_scalarmult_base(u8(key.data()), u8(secretKey.data()));
  return key;
}

std::optional<SessionKeys> deriveSessionKeys(Role role, const KeyPair& ephemeral,
                                             const KeyPair& identity, const SecureHello& peer) {
  sodiumReady();
  std::array<std::byte, 2 * kKeyBytes> shared{};
  if (crypto_scalarmult(u8(shared.data()), u8(ephemeral.secretKey.data()),
                        u8(peer.ephemeral.data())) != 0 ||
      crypto_scalarmult(u8(shared.data() + kKeyBytes), u8(identity.secretKey.data()),
                        u8(peer.identity.data())) != 0) {
    sodium_memzero(shared.data(), shared.size());
    return std::nullopt;
  }
  const bool host = role == Role::kHost;
  const SecureHello mine{ephemeral.publicKey, identity.publicKey};
  const SecureHello& first = host ? mine : peer;
  const SecureHello& second = host ? peer : mine;
  SessionKeys keys;
  crypto_generichash_state state;
  crypto_generichash_init(&state, nullptr, 0, kKeyBytes);
  hashUpdate(state, std::as_bytes(std::span(kTranscriptLabel)));
  for (const SecureHello* hello : {&first, &second}) {
    hashUpdate(state, hello->ephemeral);
    hashUpdate(state, hello->identity);
  }
  crypto_generichash_final(&state, u8(keys.transcript.data()), kKeyBytes);

  std::array<std::byte, 2 * kKeyBytes> material{};
  crypto_generichash_init(&state, nullptr, 0, material.size());
  hashUpdate(state, shared);
  hashUpdate(state, keys.transcript);
  crypto_generichash_final(&state, u8(material.data()), material.size());
  std::copy_n(material.begin(), kKeyBytes, keys.hostToDevice.begin());
  std::copy_n(material.begin() + kKeyBytes, kKeyBytes, keys.deviceToHost.begin());
  sodium_memzero(shared.data(), shared.size());
  sodium_memzero(material.data(), material.size());
  return keys;
}

struct SecureChannel::State {
  crypto_secretstream_xchacha20poly1305_state push{};
  crypto_secretstream_xchacha20poly1305_state pull{};
  Key32 pullKey{};
};

SecureChannel::SecureChannel()
    : state_(std::make_unique<State>()),
      out_(kStreamHeaderBytes + kRecordLengthBytes + kRecordMaxBytes),
      in_(kRecordMaxBytes),
      plain_(kRecordPlainBytes) {
  sodiumReady();
  reset();
}

SecureChannel::~SecureChannel() {
  reset();
}

void SecureChannel::reset() {
  sodium_memzero(state_.get(), sizeof(State));
  sodium_memzero(plain_.data(), plain_.size());
  started_ = confirmed_ = broken_ = false;
  headerRead_ = lengthRead_ = false;
  outBegin_ = outEnd_ = inHave_ = plainBegin_ = plainEnd_ = 0;
  inNeed_ = kStreamHeaderBytes;
}

void SecureChannel::start(const SessionKeys& keys, Role role) {
  reset();
  const bool host = role == Role::kHost;
  const Key32& pushKey = host ? keys.hostToDevice : keys.deviceToHost;
  const Key32& pullKey = host ? keys.deviceToHost : keys.hostToDevice;
  std::copy(pullKey.begin(), pullKey.end(), state_->pullKey.begin());
  transcript_ = keys.transcript;
  crypto_secretstream_xchacha20poly1305_init_push(&state_->push, u8(out_.data()),
                                                  u8(pushKey.data()));
  outEnd_ = kStreamHeaderBytes;
  started_ = true;
  std::array<std::byte, kConfirmBytes> confirm{};
  std::memcpy(confirm.data(), kConfirmLabel.data(), kConfirmLabel.size());
  std::copy(transcript_.begin(), transcript_.end(), confirm.begin() + kConfirmLabel.size());
  appendRecord(confirm);
}

std::size_t SecureChannel::seal(std::span<const std::byte> plain) {
  if (!started_ || broken_ || outBegin_ < outEnd_) {
    return 0;
  }
  outBegin_ = outEnd_ = 0;
  return appendRecord(plain);
}

std::size_t SecureChannel::appendRecord(std::span<const std::byte> plain) {
  const std::size_t take = std::min(plain.size(), kRecordPlainBytes);
  const std::size_t cipher = take + kRecordTagBytes;
  std::byte* at = out_.data() + outEnd_;
  for (std::size_t i = 0; i < kRecordLengthBytes; ++i) {
    at[i] = static_cast<std::byte>((cipher >> (8 * i)) & 0xFFU);
  }
  crypto_secretstream_xchacha20poly1305_push(&state_->push, u8(at + kRecordLengthBytes), nullptr,
                                             u8(plain.data()), take, nullptr, 0, 0);
  outEnd_ += kRecordLengthBytes + cipher;
  return take;
}

std::span<const std::byte> SecureChannel::pending() const {
  return std::span(out_).subspan(outBegin_, outEnd_ - outBegin_);
}

void SecureChannel::sent(std::size_t bytes) {
  outBegin_ = std::min(outEnd_, outBegin_ + bytes);
}

std::span<std::byte> SecureChannel::writable() {
  if (!started_ || broken_ || hasPlain()) {
    return {};
  }
  return std::span(in_).subspan(inHave_, inNeed_ - inHave_);
}

void SecureChannel::commit(std::size_t bytes) {
  inHave_ = std::min(inNeed_, inHave_ + bytes);
}

ProtocolResult<void> SecureChannel::openRecord() {
  if (!headerRead_) {
    if (crypto_secretstream_xchacha20poly1305_init_pull(&state_->pull, u8(in_.data()),
                                                        u8(state_->pullKey.data())) != 0) {
      return protocolFail(ProtocolErrc::kMalformed, "secure stream: bad header");
    }
    headerRead_ = true;
    inNeed_ = kRecordLengthBytes;
  } else if (!lengthRead_) {
    std::size_t length = 0;
    for (std::size_t i = 0; i < kRecordLengthBytes; ++i) {
      length |= std::to_integer<std::size_t>(in_[i]) << (8 * i);
    }
    if (length < kRecordTagBytes || length > kRecordMaxBytes) {
      return protocolFail(ProtocolErrc::kOversized, "secure stream: record length out of range");
    }
    lengthRead_ = true;
    inNeed_ = length;
  } else {
    unsigned long long plainBytes = 0;
    unsigned char tag = 0;
    if (crypto_secretstream_xchacha20poly1305_pull(&state_->pull, u8(plain_.data()), &plainBytes,
                                                   &tag, u8(in_.data()), inNeed_, nullptr,
                                                   0) != 0 ||
        tag != 0) {
      return protocolFail(ProtocolErrc::kBadCrc, "secure stream: a record failed to decrypt");
    }
    lengthRead_ = false;
    inNeed_ = kRecordLengthBytes;
    if (!confirmed_) {
      if (plainBytes != kConfirmBytes ||
          std::memcmp(plain_.data(), kConfirmLabel.data(), kConfirmLabel.size()) != 0 ||
          sodium_memcmp(plain_.data() + kConfirmLabel.size(), transcript_.data(), kKeyBytes) != 0) {
        return protocolFail(ProtocolErrc::kMalformed, "secure stream: bad key confirmation");
      }
      confirmed_ = true;
    } else {
      plainBegin_ = 0;
      plainEnd_ = plainBytes;
    }
  }
  inHave_ = 0;
  return {};
}

ProtocolResult<std::size_t> SecureChannel::read(std::span<std::byte> out) {
  if (broken_) {
    return protocolFail(ProtocolErrc::kMalformed, "secure stream: broken earlier");
  }
  if (!hasPlain() && started_ && inHave_ == inNeed_) {
    if (auto opened = openRecord(); !opened) {
      broken_ = true;
      return std::unexpected(opened.error());
    }
  }
  const std::size_t n = std::min(out.size(), plainEnd_ - plainBegin_);
  if (n > 0) {
    std::memcpy(out.data(), plain_.data() + plainBegin_, n);
    plainBegin_ += n;
  }
  return n;
}

}  // namespace smx::protocol
