#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "smx/sim/ply_io.hpp"
#include "smx/sim/scene.hpp"

// Triangle meshes for the simulator: PLY (ascii 1.0, binary_little_endian 1.0, binary_big_endian
// 1.0) and Wavefront OBJ (docs/scene-format.md, "Mesh files"). Polygons are fan-triangulated;
// everything but positions and faces is skipped. The same PLY reader reads point clouds.
//
// Not a mesh library (assimp): its ASCII number parser is not correctly rounded (1-ulp changes
// to shipped bunny vertices, so renders would change), its OBJ importer duplicates vertices per
// face corner, and its PLY parser has had heap overflows on hostile files.
//
// Init-time code: allocates. No exception leaves these functions; every failure is a MeshError.
namespace smx::sim {

struct MeshError {
  std::string file;     // the path as given to loadMesh(); empty for parseMesh()
  std::string problem;  // for an end user; text formats start with the line: "line 12: ..."

  // "file: problem", leaving out an empty file.
  [[nodiscard]] std::string message() const;
};

enum class MeshFormat { kPly, kObj };

// Reads a PLY or OBJ file, chosen by the extension (.ply / .obj, any case). Mesh::path is `path`
// as given; vertices and triangles are as in the file (indices 0-based, no welding, no
// reordering). A mesh without triangles is an error.
[[nodiscard]] std::expected<Mesh, MeshError> loadMesh(const std::filesystem::path& path);

// The same from the file's bytes in memory (Mesh::path stays empty).
[[nodiscard]] std::expected<Mesh, MeshError> parseMesh(std::string_view bytes, MeshFormat format);

// Point clouds: the vertices of a PLY file (any encoding above, x, y, z and optional red, green,
// blue, absent: 0), e.g. what writePlyPoints writes. A file with faces is a mesh, not a cloud,
// and an error. Errors are messages naming the file.
[[nodiscard]] std::expected<std::vector<PlyPoint>, std::string> readPlyPoints(
    const std::filesystem::path& path);

}  // namespace smx::sim
