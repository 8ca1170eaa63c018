#pragma once

#include <cstddef>
#include <expected>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "smx/update/update_error.hpp"

// Files written so that a crash leaves the old file or the new one, never a mix: a temporary
// beside the target, fsync, rename (or link, to refuse replacing), fsync of the directory.
namespace smx::update {

enum class Replace { kAllow, kRefuse };

[[nodiscard]] std::expected<void, UpdateError> writeFileAtomic(const std::filesystem::path& path,
                                                               std::span<const std::byte> bytes,
                                                               unsigned mode, Replace replace);

// A file that must not exist yet (O_EXCL, no symlink followed), with exactly `mode`, fsynced.
[[nodiscard]] std::expected<void, UpdateError> writeNewFile(const std::filesystem::path& path,
                                                            std::span<const std::byte> bytes,
                                                            unsigned mode);
[[nodiscard]] std::expected<void, UpdateError> syncDirectory(const std::filesystem::path& dir);

// The whole file, refused (kTooLarge) before reading when it is larger than maxBytes.
[[nodiscard]] std::expected<std::vector<std::byte>, UpdateError> readFile(
    const std::filesystem::path& path, std::size_t maxBytes);

[[nodiscard]] std::span<const std::byte> asBytes(const std::string& text);

}  // namespace smx::update
