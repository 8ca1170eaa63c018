#include "smx/sim/ply_io.hpp"

#include <bit>
#include <cstring>
#include <fstream>
#include <vector>

namespace smx::sim {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the binary PLY writer stores floats in the host's byte order");

constexpr std::size_t kRecordBytes = 3 * sizeof(float) + 3;

std::unexpected<std::string> failure(const std::filesystem::path& path, const std::string& what) {
  return std::unexpected(path.string() + ": " + what);
}

}  // namespace

std::expected<void, std::string> writePlyPoints(const std::filesystem::path& path,
                                                std::span<const PlyPoint> points) {
  std::ofstream out(path, std::ios::binary);
  if (!out) {
    return failure(path, "cannot open for writing");
  }
  out << "ply\nformat binary_little_endian 1.0\ncomment stripemux range output, metres\n"
      << "element vertex " << points.size() << "\n"
      << "property float x\nproperty float y\nproperty float z\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  std::vector<char> body(points.size() * kRecordBytes);
  char* at = body.data();
  for (const PlyPoint& p : points) {
    std::memcpy(at, &p.x, sizeof(float));
    std::memcpy(at + 4, &p.y, sizeof(float));
    std::memcpy(at + 8, &p.z, sizeof(float));
    at[12] = static_cast<char>(p.r);
    at[13] = static_cast<char>(p.g);
    at[14] = static_cast<char>(p.b);
    at += kRecordBytes;
  }
  out.write(body.data(), static_cast<std::streamsize>(body.size()));
  // Buffered bytes are written at close; a full disk shows there, not at write().
  out.close();
  if (!out) {
    return failure(path, "write failed");
  }
  return {};
}

}  // namespace smx::sim
