#include "smx/update/keys.hpp"

#include <sodium.h>

#include <algorithm>
#include <cstdio>
#include <ranges>
#include <vector>

#include "base64.hpp"
#include "smx/update/file_io.hpp"
#include "sodium_init.hpp"

namespace smx::update {
namespace {

// minisign's layouts (minisign.h): public key "Ed" + id + key; secret key "Ed", KDF algorithm
// (zero: unencrypted), checksum algorithm "B2", KDF salt, opslimit, memlimit, then id + secret
// key + BLAKE2b-256 checksum of "Ed" + id + secret key.
constexpr std::size_t kPublicSize = 2 + 8 + 32;
constexpr std::size_t kSaltSize = 32;
constexpr std::size_t kSecretSize = 2 + 2 + 2 + kSaltSize + 8 + 8 + 8 + 64 + 32;
constexpr std::size_t kMaxKeyFile = 4096;
constexpr std::string_view kPublicComment = "untrusted comment: minisign public key ";
constexpr std::string_view kSecretComment = "untrusted comment: minisign secret key";

UpdateError malformed(std::string_view source, const std::string& what) {
  return {UpdateReason::kMalformed, std::string(source) + ": " + what};
}

std::array<std::uint8_t, 32> checksum(const SecretKey& key) {
  std::vector<std::uint8_t> input = {'E', 'd'};
  input.insert(input.end(), key.id.begin(), key.id.end());
  input.insert(input.end(), key.key.begin(), key.key.end());
  std::array<std::uint8_t, 32> sum{};
  crypto_generichash(sum.data(), sum.size(), input.data(), input.size(), nullptr, 0);
  return sum;
}

// The text's second line when it has a comment line first, else the text; without '\n'.
std::string_view keyLine(std::string_view text, std::string_view comment) {
  if (text.starts_with(comment)) {
    const auto end = text.find('\n');
    text = end == std::string_view::npos ? std::string_view{} : text.substr(end + 1);
  }
  const auto end = text.find('\n');
  return end == std::string_view::npos ? text : text.substr(0, end);
}

}  // namespace

KeyPair keyPairFromSeed(std::span<const std::uint8_t, 32> seed) {
  initSodium();
  KeyPair pair;
  crypto_sign_seed_keypair(pair.pub.key.data(), pair.secret.key.data(), seed.data());
  std::array<std::uint8_t, crypto_generichash_BYTES> digest{};
  crypto_generichash(digest.data(), digest.size(), seed.data(), seed.size(), nullptr, 0);
  std::copy_n(digest.begin(), pair.pub.id.size(), pair.pub.id.begin());
  pair.secret.id = pair.pub.id;
  sodium_memzero(digest.data(), digest.size());
  return pair;
}

KeyPair generateKeyPair() {
  initSodium();
  std::array<std::uint8_t, 32> seed{};
  randombytes_buf(seed.data(), seed.size());
  KeyPair pair = keyPairFromSeed(seed);
  sodium_memzero(seed.data(), seed.size());
  return pair;
}

std::string keyIdHex(const KeyId& id) {
  std::string hex;
  for (const std::uint8_t byte : std::views::reverse(id)) {
    std::array<char, 3> digits{};
    std::snprintf(digits.data(), digits.size(), "%02X", byte);
    hex += digits.data();
  }
  // minisign prints it with PRIX64: no leading zeros.
  const auto first = std::min(hex.find_first_not_of('0'), hex.size() - 1);
  return hex.substr(first);
}

std::string publicKeyLine(const PublicKey& key) {
  std::vector<std::uint8_t> raw = {'E', 'd'};
  raw.insert(raw.end(), key.id.begin(), key.id.end());
  raw.insert(raw.end(), key.key.begin(), key.key.end());
  return toBase64(raw);
}

std::string formatPublicKey(const PublicKey& key) {
  return std::string(kPublicComment) + keyIdHex(key.id) + "\n" + publicKeyLine(key) + "\n";
}

std::string formatSecretKey(const SecretKey& key) {
  std::vector<std::uint8_t> raw = {'E', 'd', 0, 0, 'B', '2'};
  raw.resize(raw.size() + kSaltSize + 8 + 8, 0);  // no KDF: salt and limits unused
  raw.insert(raw.end(), key.id.begin(), key.id.end());
  raw.insert(raw.end(), key.key.begin(), key.key.end());
  const auto sum = checksum(key);
  raw.insert(raw.end(), sum.begin(), sum.end());
  std::string text = std::string(kSecretComment) + "\n" + toBase64(raw) + "\n";
  sodium_memzero(raw.data(), raw.size());
  return text;
}

std::expected<PublicKey, UpdateError> parsePublicKey(std::string_view text,
                                                     std::string_view source) {
  const auto raw = fromBase64(keyLine(text, "untrusted comment:"));
  if (!raw || raw->size() != kPublicSize || (*raw)[0] != 'E' || (*raw)[1] != 'd') {
    return std::unexpected(malformed(
        source, "not a minisign Ed25519 public key (a line \"RW\" + 54 base64 characters)"));
  }
  PublicKey key;
  std::copy_n(raw->begin() + 2, key.id.size(), key.id.begin());
  std::copy_n(raw->begin() + 10, key.key.size(), key.key.begin());
  return key;
}

std::expected<SecretKey, UpdateError> parseSecretKey(std::string_view text,
                                                     std::string_view source) {
  initSodium();
  auto raw = fromBase64(keyLine(text, "untrusted comment:"));
  if (!raw || raw->size() != kSecretSize || (*raw)[0] != 'E' || (*raw)[1] != 'd' ||
      (*raw)[4] != 'B' || (*raw)[5] != '2') {
    return std::unexpected(malformed(source, "not a minisign Ed25519 secret key"));
  }
  if ((*raw)[2] != 0 || (*raw)[3] != 0) {
    return std::unexpected(malformed(
        source, "the secret key is password-protected; use an unencrypted one (minisign -G -W)"));
  }
  SecretKey key;
  const std::size_t idAt = 6 + kSaltSize + 16;
  std::copy_n(raw->begin() + static_cast<std::ptrdiff_t>(idAt), key.id.size(), key.id.begin());
  std::copy_n(raw->begin() + static_cast<std::ptrdiff_t>(idAt + 8), key.key.size(),
              key.key.begin());
  // minisign 0.11 leaves the checksum of an unencrypted key zero; ours writes it.
  const auto sum = checksum(key);
  const bool match =
      std::equal(sum.begin(), sum.end(), raw->end() - 32) ||
      std::all_of(raw->end() - 32, raw->end(), [](std::uint8_t b) { return b == 0; });
  sodium_memzero(raw->data(), raw->size());
  if (!match) {
    return std::unexpected(malformed(source, "the secret key's checksum does not match"));
  }
  return key;
}

std::expected<PublicKey, UpdateError> readPublicKeyFile(const std::filesystem::path& path) {
  const auto bytes = readFile(path, kMaxKeyFile);
  if (!bytes) {
    return std::unexpected(bytes.error());
  }
  return parsePublicKey(
      std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size()), path.string());
}

std::expected<SecretKey, UpdateError> readSecretKeyFile(const std::filesystem::path& path) {
  auto bytes = readFile(path, kMaxKeyFile);
  if (!bytes) {
    return std::unexpected(bytes.error());
  }
  auto key = parseSecretKey(
      std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size()), path.string());
  sodium_memzero(bytes->data(), bytes->size());
  return key;
}

std::expected<void, UpdateError> writePublicKeyFile(const std::filesystem::path& path,
                                                    const PublicKey& key) {
  return writeFileAtomic(path, asBytes(formatPublicKey(key)), 0644, Replace::kRefuse);
}

std::expected<void, UpdateError> writeSecretKeyFile(const std::filesystem::path& path,
                                                    const SecretKey& key) {
  std::string text = formatSecretKey(key);
  auto written = writeFileAtomic(path, asBytes(text), 0600, Replace::kRefuse);
  sodium_memzero(text.data(), text.size());
  return written;
}

}  // namespace smx::update
