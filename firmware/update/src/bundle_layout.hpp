#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

// The fixed parts of a bundle (docs/update.md#bundle): the 24-byte header (magic, manifest size,
// reserved zero, payload size) and the 12-byte trailer (signature size, end magic). Little-endian.
namespace smx::update::layout {

inline constexpr std::array<char, 8> kMagic = {'S', 'M', 'X', 'B', 'N', 'D', 'L', '1'};
inline constexpr std::array<char, 8> kEndMagic = {'S', 'M', 'X', 'S', 'I', 'G', 'N', '1'};
inline constexpr std::size_t kManifestSizeAt = 8;
inline constexpr std::size_t kReservedAt = 12;
inline constexpr std::size_t kPayloadSizeAt = 16;
// The trusted comment of every bundle signature.
inline constexpr std::string_view kTrustedComment = "stripemux-bundle/1";

inline std::uint64_t load(std::span<const std::byte> bytes, std::size_t at, std::size_t size) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < size; ++i) {
    value |= static_cast<std::uint64_t>(bytes[at + i]) << (8 * i);
  }
  return value;
}

}  // namespace smx::update::layout
