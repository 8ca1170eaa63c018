#pragma once

#include <cstddef>
#include <expected>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "smx/update/update_error.hpp"

// Files written so that a crash leaves the old file or the new one, never a mix: a temporary
// beside the target, fsync, rename (or link, to refuse replacing), fsync of the directory.
namespace smx::update {

enum class Replace { kAllow, kRefuse };

// The steps of writeFileAtomic(), in order, as its hook is told them (the state files' crash
// points, docs/config.md).
inline constexpr std::string_view kAtomicWriteSteps[] = {"temp-created", "temp-written",
                                                         "temp-synced", "renamed", "dir-synced"};
using StepHook = std::function<void(std::string_view step)>;

// The temporary is `<path>.tmp` (tempPathOf), so what a crash left is found by its name.
// `onStep` (may be empty) is called after each step of kAtomicWriteSteps.
[[nodiscard]] std::expected<void, UpdateError> writeFileAtomic(const std::filesystem::path& path,
                                                               std::span<const std::byte> bytes,
                                                               unsigned mode, Replace replace,
                                                               const StepHook& onStep = {});
[[nodiscard]] std::filesystem::path tempPathOf(const std::filesystem::path& path);

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
