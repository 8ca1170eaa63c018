#include "smx/update/signature.hpp"

#include <sodium.h>

#include <algorithm>
#include <array>
#include <optional>
#include <vector>

#include "base64.hpp"
#include "sodium_init.hpp"

namespace smx::update {
namespace {

// minisign's signature: "ED" (prehashed), key id, Ed25519 signature of BLAKE2b-512(data).
constexpr std::size_t kSignatureSize = 2 + 8 + crypto_sign_BYTES;
constexpr std::string_view kTrustedPrefix = "trusted comment: ";

using Prehash = std::array<std::uint8_t, crypto_generichash_BYTES_MAX>;

Prehash prehash(std::span<const std::byte> data) {
  Prehash hash{};
  crypto_generichash(hash.data(), hash.size(), reinterpret_cast<const unsigned char*>(data.data()),
                     data.size(), nullptr, 0);
  return hash;
}

UpdateError malformed(const std::string& what) {
  return {UpdateReason::kMalformed, "signature: " + what};
}

// The next line without its '\n'; a line with no '\n' after it is not a line.
std::optional<std::string_view> takeLine(std::string_view& text) {
  const auto end = text.find('\n');
  if (end == std::string_view::npos) {
    return std::nullopt;
  }
  const auto line = text.substr(0, end);
  text.remove_prefix(end + 1);
  return line;
}

bool printable(std::string_view text) {
  return std::all_of(text.begin(), text.end(), [](char c) { return c >= 0x20 && c < 0x7f; });
}

}  // namespace

std::string sign(const SecretKey& key, std::span<const std::byte> data,
                 std::string_view trustedComment) {
  initSodium();
  const Prehash hash = prehash(data);
  std::vector<std::uint8_t> raw = {'E', 'D'};
  raw.insert(raw.end(), key.id.begin(), key.id.end());
  std::array<std::uint8_t, crypto_sign_BYTES> signature{};
  crypto_sign_detached(signature.data(), nullptr, hash.data(), hash.size(), key.key.data());
  raw.insert(raw.end(), signature.begin(), signature.end());

  // The global signature covers the signature and the trusted comment together.
  std::vector<std::uint8_t> global(signature.begin(), signature.end());
  global.insert(global.end(), trustedComment.begin(), trustedComment.end());
  std::array<std::uint8_t, crypto_sign_BYTES> globalSignature{};
  crypto_sign_detached(globalSignature.data(), nullptr, global.data(), global.size(),
                       key.key.data());
  return std::string(kUntrustedComment) + "\n" + toBase64(raw) + "\n" +
         std::string(kTrustedPrefix) + std::string(trustedComment) + "\n" +
         toBase64(globalSignature) + "\n";
}

std::expected<KeyId, UpdateError> verify(std::span<const std::byte> data,
                                         std::string_view signature,
                                         std::span<const PublicKey> trusted) {
  initSodium();
  std::string_view rest = signature;
  const auto untrusted = takeLine(rest);
  const auto encoded = takeLine(rest);
  const auto comment = takeLine(rest);
  const auto encodedGlobal = takeLine(rest);
  if (!untrusted || !encoded || !comment || !encodedGlobal || !rest.empty()) {
    return std::unexpected(malformed("not four lines"));
  }
  if (*untrusted != kUntrustedComment) {
    return std::unexpected(
        malformed("the first line is not \"" + std::string(kUntrustedComment) + "\""));
  }
  const auto raw = fromBase64(*encoded);
  if (!raw || raw->size() != kSignatureSize || (*raw)[0] != 'E' || (*raw)[1] != 'D') {
    return std::unexpected(
        malformed("the second line is not a prehashed Ed25519 signature (\"ED\")"));
  }
  if (!comment->starts_with(kTrustedPrefix) || !printable(*comment) ||
      comment->size() - kTrustedPrefix.size() > kMaxTrustedCommentSize) {
    return std::unexpected(malformed("the third line is not a trusted comment"));
  }
  const auto global = fromBase64(*encodedGlobal);
  if (!global || global->size() != crypto_sign_BYTES) {
    return std::unexpected(malformed("the fourth line is not a global signature"));
  }

  KeyId id{};
  std::copy_n(raw->begin() + 2, id.size(), id.begin());
  const auto key =
      std::find_if(trusted.begin(), trusted.end(), [&](const PublicKey& k) { return k.id == id; });
  if (key == trusted.end()) {
    return std::unexpected(
        UpdateError{UpdateReason::kUnknownKey,
                    "signature: made by key " + keyIdHex(id) + ", which is not trusted"});
  }
  const std::uint8_t* sig = raw->data() + 10;
  const Prehash hash = prehash(data);
  if (crypto_sign_verify_detached(sig, hash.data(), hash.size(), key->key.data()) != 0) {
    return std::unexpected(
        UpdateError{UpdateReason::kBadSignature, "signature: does not match the " +
                                                     std::to_string(data.size()) +
                                                     " signed bytes (key " + keyIdHex(id) + ")"});
  }
  std::vector<std::uint8_t> signedComment(sig, sig + crypto_sign_BYTES);
  const auto text = comment->substr(kTrustedPrefix.size());
  signedComment.insert(signedComment.end(), text.begin(), text.end());
  if (crypto_sign_verify_detached(global->data(), signedComment.data(), signedComment.size(),
                                  key->key.data()) != 0) {
    return std::unexpected(UpdateError{UpdateReason::kBadSignature,
                                       "signature: the trusted comment's signature does not match "
                                       "(key " +
                                           keyIdHex(id) + ")"});
  }
  return id;
}

}  // namespace smx::update
