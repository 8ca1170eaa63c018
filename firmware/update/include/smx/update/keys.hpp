#pragma once

#include <array>
#include <cstdint>
#include <expected>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "smx/update/update_error.hpp"

// Ed25519 keys (libsodium) in minisign's file formats: the public key is the line
// "RW…" (base64 of "Ed", the 8-byte key id, the 32-byte key); the secret key is minisign's
// unencrypted secret key (`minisign -G -W`). docs/update.md#keys.
namespace smx::update {

using KeyId = std::array<std::uint8_t, 8>;

struct PublicKey {
  KeyId id{};
  std::array<std::uint8_t, 32> key{};
};

struct SecretKey {
  KeyId id{};
  std::array<std::uint8_t, 64> key{};  // libsodium's: seed, then the public key
};

struct KeyPair {
  SecretKey secret;
  PublicKey pub;
};

[[nodiscard]] KeyPair generateKeyPair();
// The same seed gives the same pair (test keys, fuzz seeds); the id is taken from the seed.
[[nodiscard]] KeyPair keyPairFromSeed(std::span<const std::uint8_t, 32> seed);

// As minisign prints it: the id read as a little-endian 64-bit number, upper-case hex without
// leading zeros.
[[nodiscard]] std::string keyIdHex(const KeyId& id);

// The public key's "RW…" line alone, and the two-line file minisign writes.
[[nodiscard]] std::string publicKeyLine(const PublicKey& key);
[[nodiscard]] std::string formatPublicKey(const PublicKey& key);
[[nodiscard]] std::string formatSecretKey(const SecretKey& key);
// A public key file, or its "RW…" line alone; `source` names it in errors.
[[nodiscard]] std::expected<PublicKey, UpdateError> parsePublicKey(std::string_view text,
                                                                   std::string_view source);
[[nodiscard]] std::expected<SecretKey, UpdateError> parseSecretKey(std::string_view text,
                                                                   std::string_view source);

[[nodiscard]] std::expected<PublicKey, UpdateError> readPublicKeyFile(
    const std::filesystem::path& path);
[[nodiscard]] std::expected<SecretKey, UpdateError> readSecretKeyFile(
    const std::filesystem::path& path);
// Both refuse to replace an existing file (kExists); the secret key is written 0600.
[[nodiscard]] std::expected<void, UpdateError> writePublicKeyFile(const std::filesystem::path& path,
                                                                  const PublicKey& key);
[[nodiscard]] std::expected<void, UpdateError> writeSecretKeyFile(const std::filesystem::path& path,
                                                                  const SecretKey& key);

}  // namespace smx::update
