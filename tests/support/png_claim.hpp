#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "smx/protocol/crc32.hpp"

// Hand-made PNGs for tests of the readers' size limits: a valid signature, an IHDR claiming any
// size (8-bit RGB) with a correct CRC, an IDAT holding an empty zlib stream and IEND, 65 bytes
// in all. A reader that trusts the header allocates width x height pixels before it finds that
// the data is missing.
namespace smx::test {

inline std::vector<std::byte> pngClaiming(std::uint32_t width, std::uint32_t height) {
  std::vector<std::byte> png;
  const auto put = [&](std::initializer_list<std::uint8_t> bytes) {
    for (const std::uint8_t b : bytes) {
      png.push_back(std::byte{b});
    }
  };
  const auto put32 = [&](std::uint32_t v) {
    put({static_cast<std::uint8_t>(v >> 24U), static_cast<std::uint8_t>(v >> 16U),
         static_cast<std::uint8_t>(v >> 8U), static_cast<std::uint8_t>(v)});
  };
  const auto chunk = [&](std::string_view type, std::span<const std::uint8_t> data) {
    put32(static_cast<std::uint32_t>(data.size()));
    const std::size_t typeAt = png.size();
    for (const char c : type) {
      put({static_cast<std::uint8_t>(c)});
    }
    for (const std::uint8_t b : data) {
      put({b});
    }
    put32(protocol::crc32(std::span(png).subspan(typeAt)));
  };
  put({0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'});
  const std::uint8_t ihdr[] = {static_cast<std::uint8_t>(width >> 24U),
                               static_cast<std::uint8_t>(width >> 16U),
                               static_cast<std::uint8_t>(width >> 8U),
                               static_cast<std::uint8_t>(width),
                               static_cast<std::uint8_t>(height >> 24U),
                               static_cast<std::uint8_t>(height >> 16U),
                               static_cast<std::uint8_t>(height >> 8U),
                               static_cast<std::uint8_t>(height),
                               8,  // bit depth
                               2,  // colour type: RGB
                               0,
                               0,
                               0};
  chunk("IHDR", ihdr);
  const std::uint8_t emptyZlib[] = {0x78, 0x9C, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01};
  chunk("IDAT", emptyZlib);
  chunk("IEND", {});
  return png;
}

}  // namespace smx::test
