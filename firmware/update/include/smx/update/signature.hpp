#pragma once

#include <cstddef>
#include <expected>
#include <span>
#include <string>
#include <string_view>

#include "smx/update/keys.hpp"
#include "smx/update/update_error.hpp"

// minisign's prehashed signature ("ED": Ed25519 over BLAKE2b-512 of the data) with its trusted
// comment and global signature, so `minisign -V -P KEY -m FILE` checks what sign() writes.
// docs/update.md#signatures.
namespace smx::update {

// The one untrusted comment line accepted: minisign does not authenticate it, so any other
// text would be a byte of the bundle that could change unnoticed.
inline constexpr std::string_view kUntrustedComment = "untrusted comment: stripemux signature";
inline constexpr std::size_t kMaxTrustedCommentSize = 1024;

// The signature file's text; trustedComment is one line of printable ASCII, at most
// kMaxTrustedCommentSize bytes.
[[nodiscard]] std::string sign(const SecretKey& key, std::span<const std::byte> data,
                               std::string_view trustedComment);

// The id of the trusted key whose signature over `data` this is. kUnknownKey when the id is
// none of `trusted`, kBadSignature when the key's signature does not match.
[[nodiscard]] std::expected<KeyId, UpdateError> verify(std::span<const std::byte> data,
                                                       std::string_view signature,
                                                       std::span<const PublicKey> trusted);

}  // namespace smx::update
