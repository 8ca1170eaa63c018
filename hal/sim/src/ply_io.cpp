#include "smx/sim/ply_io.hpp"

#include <bit>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

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

std::expected<std::vector<PlyPoint>, std::string> readPlyPoints(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return failure(path, "cannot open");
  }
  std::string line;
  if (!std::getline(in, line) || line != "ply") {
    return failure(path, "not a PLY file (no 'ply' magic)");
  }
  bool binary = false;
  bool sawFormat = false;
  std::size_t count = 0;
  std::vector<std::string> properties;
  bool inVertex = false;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "comment" || key == "obj_info" || key.empty()) {
      continue;
    }
    if (key == "format") {
      std::string kind;
      words >> kind;
      if (kind != "binary_little_endian" && kind != "ascii") {
        return failure(path, "unsupported PLY format '" + kind + "'");
      }
      binary = kind == "binary_little_endian";
      sawFormat = true;
    } else if (key == "element") {
      std::string name;
      words >> name >> count;
      if (name != "vertex" || !properties.empty() || inVertex) {
        return failure(path, "only a single 'element vertex' is supported, found '" + name + "'");
      }
      inVertex = true;
    } else if (key == "property") {
      std::string type;
      std::string name;
      words >> type >> name;
      properties.push_back(type.append(" ").append(name));
    } else {
      return failure(path, "unexpected header line '" + line + "'");
    }
  }
  if (line != "end_header" || !sawFormat || !inVertex) {
    return failure(path, "truncated or incomplete PLY header");
  }
  const std::vector<std::string> xyz = {"float x", "float y", "float z"};
  const std::vector<std::string> xyzrgb = {"float x",   "float y",     "float z",
                                           "uchar red", "uchar green", "uchar blue"};
  const bool colour = properties == xyzrgb;
  if (properties != xyz && !colour) {
    return failure(path, "vertex properties must be float x, y, z [uchar red, green, blue]");
  }
  // The header's count must fit the file (a corrupt count must not allocate gigabytes).
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  const auto headerEnd = static_cast<std::uintmax_t>(in.tellg());
  const std::uintmax_t minBytes = colour ? kRecordBytes : 3 * sizeof(float);
  const std::uintmax_t perVertex = binary ? minBytes : 6;  // ascii: "0 0 0\n" at least
  if (ec || size < headerEnd || count > (size - headerEnd) / perVertex) {
    return failure(path, "truncated: the header announces " + std::to_string(count) +
                             " vertices, more than the file holds");
  }
  std::vector<PlyPoint> points(count);
  for (std::size_t i = 0; i < count; ++i) {
    PlyPoint& p = points[i];
    if (binary) {
      char record[kRecordBytes];
      const std::size_t bytes = colour ? kRecordBytes : 3 * sizeof(float);
      if (!in.read(record, static_cast<std::streamsize>(bytes))) {
        return failure(
            path, "truncated: " + std::to_string(i) + " of " + std::to_string(count) + " vertices");
      }
      std::memcpy(&p.x, record, sizeof(float));
      std::memcpy(&p.y, record + 4, sizeof(float));
      std::memcpy(&p.z, record + 8, sizeof(float));
      if (colour) {
        p.r = static_cast<std::uint8_t>(record[12]);
        p.g = static_cast<std::uint8_t>(record[13]);
        p.b = static_cast<std::uint8_t>(record[14]);
      }
    } else {
      int r = 0;
      int g = 0;
      int b = 0;
      if (!(in >> p.x >> p.y >> p.z) || (colour && !(in >> r >> g >> b))) {
        return failure(path, "truncated or malformed vertex " + std::to_string(i));
      }
      p.r = static_cast<std::uint8_t>(r);
      p.g = static_cast<std::uint8_t>(g);
      p.b = static_cast<std::uint8_t>(b);
    }
  }
  return points;
}

}  // namespace smx::sim
