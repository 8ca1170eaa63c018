#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <string_view>

#include "smx/protocol/secure_session.hpp"

// Long-term X25519 keys as files (docs/security.md "Key files"). A public key is one line
//   smx-x25519 <64 hex digits> [comment]
// (hosts/<name>.pub on the device, devices/<name>.pub on the host, `stripemux pair --show-key`);
// a secret key file (identity.key, host.key, mode 0600) is one line
//   smx-x25519-secret <64 hex digits>
namespace smx::protocol {

[[nodiscard]] std::string formatPublicKey(const Key32& key, std::string_view comment);
[[nodiscard]] std::expected<Key32, std::string> parsePublicKey(std::string_view text);
// 16 hex digits of BLAKE2b of the key: what a person compares, and the name of a host's file.
[[nodiscard]] std::string fingerprint(const Key32& key);

// Reads the key pair in `path`, or makes one and writes it there (0600, atomically) when the
// file does not exist. Errors name the file.
[[nodiscard]] std::expected<KeyPair, std::string> loadOrCreateIdentity(
    const std::filesystem::path& path);
// Reads a public key file (at most 1 KiB); errors name the file.
[[nodiscard]] std::expected<Key32, std::string> readPublicKeyFile(
    const std::filesystem::path& path);

}  // namespace smx::protocol
