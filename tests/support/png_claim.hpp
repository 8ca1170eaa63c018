#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "smx/protocol/crc32.hpp"

// Hand-made PNGs for tests of the readers' limits: chunks with correct CRCs in any order and of
// any claim, written without libpng.
namespace smx::test {

struct PngChunk {
  std::string type;  // 4 letters, e.g. "IHDR"
  std::vector<std::uint8_t> data;
};

inline void putBigEndian32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (const unsigned shift : {24U, 16U, 8U, 0U}) {
    out.push_back(static_cast<std::uint8_t>(v >> shift));
  }
}

// The signature, then each chunk as length, type, data and CRC.
inline std::vector<std::byte> pngOf(std::span<const PngChunk> chunks) {
  std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  for (const PngChunk& chunk : chunks) {
    putBigEndian32(png, static_cast<std::uint32_t>(chunk.data.size()));
    const std::size_t typeAt = png.size();
    png.insert(png.end(), chunk.type.begin(), chunk.type.end());
    png.insert(png.end(), chunk.data.begin(), chunk.data.end());
    putBigEndian32(png, protocol::crc32(std::as_bytes(std::span(png).subspan(typeAt))));
  }
  const auto bytes = std::as_bytes(std::span(png));
  return {bytes.begin(), bytes.end()};
}

// An IHDR chunk: no interlace, the standard compression and filter method.
inline PngChunk ihdr(std::uint32_t width, std::uint32_t height, std::uint8_t bitDepth,
                     std::uint8_t colourType) {
  PngChunk chunk{"IHDR", {}};
  putBigEndian32(chunk.data, width);
  putBigEndian32(chunk.data, height);
  chunk.data.insert(chunk.data.end(), {bitDepth, colourType, 0, 0, 0});
  return chunk;
}

// 65 bytes whose IHDR claims width x height 8-bit RGB pixels, followed by an IDAT holding an
// empty zlib stream and IEND. A reader that trusts the header allocates width x height pixels
// before it finds that the data is missing.
inline std::vector<std::byte> pngClaiming(std::uint32_t width, std::uint32_t height) {
  const PngChunk chunks[] = {ihdr(width, height, 8, 2),
                             {"IDAT", {0x78, 0x9C, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01}},
                             {"IEND", {}}};
  return pngOf(chunks);
}

}  // namespace smx::test
