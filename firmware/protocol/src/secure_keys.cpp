#include "smx/protocol/secure_keys.hpp"

#include <sodium.h>

#include <system_error>

#include "smx/update/file_io.hpp"
#include "sodium_ready.hpp"

namespace smx::protocol {

namespace {

constexpr std::string_view kPublicTag = "smx-x25519 ";
constexpr std::string_view kSecretTag = "smx-x25519-secret ";
constexpr std::size_t kHexBytes = 2 * kKeyBytes;
constexpr std::size_t kMaxKeyFileBytes = 1024;

std::string toHex(std::span<const std::byte> bytes) {
  std::string hex(2 * bytes.size() + 1, '\0');
  sodium_bin2hex(hex.data(), hex.size(), reinterpret_cast<const unsigned char*>(bytes.data()),
                 bytes.size());
  hex.pop_back();
  return hex;
}

std::expected<Key32, std::string> parseTagged(std::string_view text, std::string_view tag) {
  if (!text.starts_with(tag)) {
    return std::unexpected("does not start with \"" + std::string(tag) + "\"");
  }
  const std::string_view hex = text.substr(tag.size(), kHexBytes);
  const std::string_view rest = text.substr(tag.size() + hex.size());
  if (hex.size() != kHexBytes || (!rest.empty() && rest.front() != ' ' && rest.front() != '\n')) {
    return std::unexpected("the key is not " + std::to_string(kHexBytes) + " hex digits");
  }
  Key32 key{};
  std::size_t written = 0;
  if (sodium_hex2bin(reinterpret_cast<unsigned char*>(key.data()), key.size(), hex.data(),
                     hex.size(), nullptr, &written, nullptr) != 0 ||
      written != key.size()) {
    return std::unexpected("the key is not " + std::to_string(kHexBytes) + " hex digits");
  }
  return key;
}

std::expected<std::string, std::string> readKeyText(const std::filesystem::path& path) {
  auto bytes = update::readFile(path, kMaxKeyFileBytes);
  if (!bytes) {
    return std::unexpected(bytes.error().message);
  }
  return std::string(reinterpret_cast<const char*>(bytes->data()), bytes->size());
}

}  // namespace

std::string formatPublicKey(const Key32& key, std::string_view comment) {
  std::string line = std::string(kPublicTag) + toHex(key);
  if (!comment.empty()) {
    line += ' ';
    line += comment;
  }
  return line + '\n';
}

std::expected<Key32, std::string> parsePublicKey(std::string_view text) {
  return parseTagged(text, kPublicTag);
}

std::string fingerprint(const Key32& key) {
  sodiumReady();
  std::array<std::byte, 8> hash{};
  crypto_generichash(reinterpret_cast<unsigned char*>(hash.data()), hash.size(),
                     reinterpret_cast<const unsigned char*>(key.data()), key.size(), nullptr, 0);
  return toHex(hash);
}

std::expected<KeyPair, std::string> loadOrCreateIdentity(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    KeyPair pair = generateKeyPair();
    std::string text = std::string(kSecretTag) + toHex(pair.secretKey) + '\n';
    auto written =
        update::writeFileAtomic(path, update::asBytes(text), 0600, update::Replace::kRefuse);
    sodium_memzero(text.data(), text.size());
    if (!written) {
      return std::unexpected(written.error().message);
    }
    return pair;
  }
  auto text = readKeyText(path);
  if (!text) {
    return std::unexpected(text.error());
  }
  auto secret = parseTagged(*text, kSecretTag);
  sodium_memzero(text->data(), text->size());
  if (!secret) {
    return std::unexpected(path.string() + ": " + secret.error());
  }
  return KeyPair{publicKeyOf(*secret), *secret};
}

std::expected<Key32, std::string> readPublicKeyFile(const std::filesystem::path& path) {
  auto text = readKeyText(path);
  if (!text) {
    return std::unexpected(text.error());
  }
  auto key = parsePublicKey(*text);
  if (!key) {
    return std::unexpected(path.string() + ": " + key.error());
  }
  return key;
}

}  // namespace smx::protocol
