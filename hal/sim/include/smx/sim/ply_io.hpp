#pragma once

#include <cstdint>
#include <expected>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

// Point clouds as PLY files (range output: `stripemux decode`, the host tool). Written as
// binary_little_endian 1.0 with float x, y, z (metres) and uchar red, green, blue per vertex —
// what MeshLab, Open3D and CloudCompare open. Errors are messages naming the file.
namespace smx::sim {

struct PlyPoint {
  float x = 0;
  float y = 0;
  float z = 0;
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
};

[[nodiscard]] std::expected<void, std::string> writePlyPoints(const std::filesystem::path& path,
                                                              std::span<const PlyPoint> points);

// Reads what writePlyPoints writes, and the same vertex layout in ascii; colour is optional
// (absent: 0). Other layouts (faces, other properties or types) are errors naming the file.
[[nodiscard]] std::expected<std::vector<PlyPoint>, std::string> readPlyPoints(
    const std::filesystem::path& path);

}  // namespace smx::sim
