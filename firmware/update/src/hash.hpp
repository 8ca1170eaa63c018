#pragma once

#include <cstddef>
#include <span>
#include <string>

namespace smx::update {

// BLAKE2b-256 of the bytes as 64 lower-case hex digits: the manifest's per-file hash.
[[nodiscard]] std::string blake2bHex(std::span<const std::byte> bytes);

}  // namespace smx::update
