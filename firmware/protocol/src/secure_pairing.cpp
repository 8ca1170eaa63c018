#include "smx/protocol/secure_pairing.hpp"

#include <sodium.h>

#include <array>

#include "sodium_ready.hpp"

namespace smx::protocol {

namespace {

constexpr std::string_view kGeneratorLabel = "stripemux pairing generator 1";
constexpr std::string_view kTranscriptLabel = "stripemux pairing 1";

auto* u8(std::byte* p) {
  return reinterpret_cast<unsigned char*>(p);
}
const auto* u8(const std::byte* p) {
  return reinterpret_cast<const unsigned char*>(p);
}
const auto* u8(std::string_view text) {
  return reinterpret_cast<const unsigned char*>(text.data());
}

Key32 keyedHash(const Key32& key, std::string_view label, const Key32& transcript) {
  Key32 out{};
  crypto_generichash_state state;
  crypto_generichash_init(&state, u8(key.data()), key.size(), out.size());
  crypto_generichash_update(&state, u8(label), label.size());
  crypto_generichash_update(&state, u8(transcript.data()), transcript.size());
  crypto_generichash_final(&state, u8(out.data()), out.size());
  return out;
}

}  // namespace

PakeShare pakeStart(std::string_view code) {
  sodiumReady();
  // The generator is the code hashed onto the group: nobody knows its discrete log.
  std::array<unsigned char, crypto_core_ristretto255_HASHBYTES> hash{};
  crypto_generichash_state state;
  crypto_generichash_init(&state, nullptr, 0, hash.size());
  crypto_generichash_update(&state, u8(kGeneratorLabel), kGeneratorLabel.size());
  crypto_generichash_update(&state, u8(code), code.size());
  crypto_generichash_final(&state, hash.data(), hash.size());
  std::array<unsigned char, crypto_core_ristretto255_BYTES> generator{};
  crypto_core_ristretto255_from_hash(generator.data(), hash.data());
  PakeShare share;
  // Only a zero scalar gives the identity (refused): draw again.
  do {
    crypto_core_ristretto255_scalar_random(u8(share.scalar.data()));
  } while (crypto_scalarmult_ristretto255(u8(share.element.data()), u8(share.scalar.data()),
                                          generator.data()) != 0);
  sodium_memzero(hash.data(), hash.size());
  return share;
}

std::optional<PairingKeys> pakeFinish(const PakeShare& mine, const Key32& peerElement,
                                      const PairRequest& request, const Key32& deviceElement,
                                      const Key32& deviceIdentity) {
  sodiumReady();
  Key32 shared{};
  if (crypto_core_ristretto255_is_valid_point(u8(peerElement.data())) != 1 ||
      crypto_scalarmult_ristretto255(u8(shared.data()), u8(mine.scalar.data()),
                                     u8(peerElement.data())) != 0) {
    return std::nullopt;
  }
  Key32 transcript{};
  crypto_generichash_state state;
  crypto_generichash_init(&state, nullptr, 0, transcript.size());
  crypto_generichash_update(&state, u8(kTranscriptLabel), kTranscriptLabel.size());
  for (const Key32* part : {&request.element, &request.identity, &deviceElement, &deviceIdentity}) {
    crypto_generichash_update(&state, u8(part->data()), part->size());
  }
  crypto_generichash_final(&state, u8(transcript.data()), transcript.size());
  Key32 key = keyedHash(shared, "key", transcript);
  PairingKeys keys{keyedHash(key, "device", transcript), keyedHash(key, "host", transcript)};
  sodium_memzero(shared.data(), shared.size());
  sodium_memzero(key.data(), key.size());
  return keys;
}

bool sameProof(const Key32& a, const Key32& b) {
  return sodium_memcmp(a.data(), b.data(), a.size()) == 0;
}

std::optional<std::string> PairingCode::open(std::int64_t nowNs) {
  if (isOpen(nowNs) || (everOpened_ && nowNs - openedNs_ < kReopenNs)) {
    return std::nullopt;
  }
  sodiumReady();
  std::uint32_t limit = 1;
  for (int i = 0; i < kDigits; ++i) {
    limit *= 10;
  }
  std::string code = std::to_string(randombytes_uniform(limit));
  code.insert(0, static_cast<std::size_t>(kDigits) - code.size(), '0');
  code_ = code;
  openedNs_ = nowNs;
  everOpened_ = true;
  attemptsLeft_ = kAttempts;
  return code;
}

bool PairingCode::isOpen(std::int64_t nowNs) const {
  return attemptsLeft_ > 0 && nowNs - openedNs_ < kLifetimeNs;
}

std::optional<std::string> PairingCode::attempt(std::int64_t nowNs) {
  if (!isOpen(nowNs)) {
    return std::nullopt;
  }
  --attemptsLeft_;
  return code_;
}

void PairingCode::close() {
  sodium_memzero(code_.data(), code_.size());
  attemptsLeft_ = 0;
}

int PairingCode::secondsLeft(std::int64_t nowNs) const {
  return isOpen(nowNs) ? static_cast<int>((kLifetimeNs - (nowNs - openedNs_)) / 1'000'000'000) : 0;
}

}  // namespace smx::protocol
