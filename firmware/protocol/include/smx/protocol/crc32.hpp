#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

// CRC-32 (IEEE 802.3, reflected 0xEDB88320, the one of zlib and Ethernet) over a message; the
// table is built at compile time. crc32Update() chains pieces: crc32Update(crc32Update(0, a), b)
// equals crc32 of a followed by b.
namespace smx::protocol {

[[nodiscard]] std::uint32_t crc32Update(std::uint32_t crc, std::span<const std::byte> bytes);
[[nodiscard]] inline std::uint32_t crc32(std::span<const std::byte> bytes) {
  return crc32Update(0, bytes);
}

}  // namespace smx::protocol
