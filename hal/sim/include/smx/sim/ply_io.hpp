#pragma once

#include <cstdint>
#include <expected>
#include <filesystem>
#include <span>
#include <string>

// Point clouds as PLY files (range output: `stripemux decode`, the host tool). Written as
// binary_little_endian 1.0 with float x, y, z (metres) and uchar red, green, blue per vertex —
// what MeshLab, Open3D and CloudCompare open. Errors are messages naming the file. Reading them
// back: readPlyPoints (mesh_io.hpp), the one PLY reader.
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

}  // namespace smx::sim
