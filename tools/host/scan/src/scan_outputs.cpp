#include "smx/scan/scan_outputs.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>

// PLY and STL are written little-endian, which is what this host is (checked below); floats are
// single precision, enough for micrometres within kilometres.
static_assert(std::endian::native == std::endian::little, "the writers assume little-endian");

namespace smx::scan {
namespace {

template <typename T>
void put(std::ostream& out, T value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof value);
}

void putVector(std::ostream& out, const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k) {
    put(out, static_cast<float>(v[k]));
  }
}

std::uint8_t byteOf(double c) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255.0));
}

std::expected<void, std::string> finish(std::ofstream& out, const std::filesystem::path& path) {
  out.flush();
  if (!out) {
    return std::unexpected("cannot write " + path.string());
  }
  return {};
}

// The PLY header and vertex records shared by clouds and meshes.
void plyVertices(std::ostream& out, const std::vector<Eigen::Vector3d>& points,
                 const std::vector<Eigen::Vector3d>& normals,
                 const std::vector<Eigen::Vector3d>& colours, std::size_t faces) {
  const bool hasNormals = normals.size() == points.size() && !points.empty();
  const bool hasColours = colours.size() == points.size() && !points.empty();
  out << "ply\nformat binary_little_endian 1.0\ncomment stripemux scan\nelement vertex "
      << points.size() << "\nproperty float x\nproperty float y\nproperty float z\n";
  if (hasNormals) {
    out << "property float nx\nproperty float ny\nproperty float nz\n";
  }
  if (hasColours) {
    out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  }
  if (faces > 0) {
    out << "element face " << faces << "\nproperty list uchar int vertex_indices\n";
  }
  out << "end_header\n";
  for (std::size_t i = 0; i < points.size(); ++i) {
    putVector(out, points[i]);
    if (hasNormals) {
      putVector(out, normals[i]);
    }
    if (hasColours) {
      for (int k = 0; k < 3; ++k) {
        put(out, byteOf(colours[i][k]));
      }
    }
  }
}

}  // namespace

std::expected<void, std::string> writeCloudPly(const std::filesystem::path& path,
                                               const Cloud& cloud) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  plyVertices(out, cloud.points, cloud.normals, cloud.colours, 0);
  return finish(out, path);
}

std::expected<void, std::string> writeMeshPly(const std::filesystem::path& path, const Mesh& mesh) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  plyVertices(out, mesh.vertices, mesh.normals, mesh.colours, mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    put(out, std::uint8_t{3});
    for (int k = 0; k < 3; ++k) {
      put(out, static_cast<std::int32_t>(t[k]));
    }
  }
  return finish(out, path);
}

std::expected<void, std::string> writeMeshObj(const std::filesystem::path& path, const Mesh& mesh) {
  std::ofstream out(path, std::ios::trunc);
  out.precision(7);
  const bool hasNormals = mesh.normals.size() == mesh.vertices.size() && !mesh.vertices.empty();
  const bool hasColours = mesh.colours.size() == mesh.vertices.size() && !mesh.vertices.empty();
  out << "# stripemux scan: metres\n";
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const auto& v = mesh.vertices[i];
    out << "v " << v.x() << ' ' << v.y() << ' ' << v.z();
    if (hasColours) {  // the common "v x y z r g b" extension
      out << ' ' << mesh.colours[i].x() << ' ' << mesh.colours[i].y() << ' ' << mesh.colours[i].z();
    }
    out << '\n';
  }
  if (hasNormals) {
    for (const auto& n : mesh.normals) {
      out << "vn " << n.x() << ' ' << n.y() << ' ' << n.z() << '\n';
    }
  }
  for (const auto& t : mesh.triangles) {  // OBJ counts from 1
    out << 'f';
    for (int k = 0; k < 3; ++k) {
      out << ' ' << t[k] + 1;
      if (hasNormals) {
        out << "//" << t[k] + 1;
      }
    }
    out << '\n';
  }
  return finish(out, path);
}

std::expected<void, std::string> writeMeshStl(const std::filesystem::path& path, const Mesh& mesh) {
  if (mesh.triangles.size() > 0xffffffffU) {
    return std::unexpected(path.string() + ": too many triangles for STL");
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  std::string header = "stripemux scan, metres";
  header.resize(80, ' ');
  out.write(header.data(), 80);
  put(out, static_cast<std::uint32_t>(mesh.triangles.size()));
  for (const auto& t : mesh.triangles) {
    const auto& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    const auto& b = mesh.vertices[static_cast<std::size_t>(t[1])];
    const auto& c = mesh.vertices[static_cast<std::size_t>(t[2])];
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() > 0) {
      n.normalize();
    }
    putVector(out, n);
    putVector(out, a);
    putVector(out, b);
    putVector(out, c);
    put(out, std::uint16_t{0});
  }
  return finish(out, path);
}

}  // namespace smx::scan
