#pragma once

#include <expected>
#include <filesystem>
#include <string>

#include "smx/scan/fusion.hpp"
#include "smx/scan/points.hpp"

// The files a scan ends in (docs/scanning.md): binary little-endian PLY, OBJ and binary STL.
// Each writer writes the path it is given (an OutputFolder's temporary path) and reports errors
// naming it.
namespace smx::scan {

// Points with normals and colours (those present), binary PLY.
[[nodiscard]] std::expected<void, std::string> writeCloudPly(const std::filesystem::path& path,
                                                             const Cloud& cloud);
// Vertices (with normals and colours when present) and triangles, binary PLY.
[[nodiscard]] std::expected<void, std::string> writeMeshPly(const std::filesystem::path& path,
                                                            const Mesh& mesh);
// Wavefront OBJ: v (with colour when present), vn, f.
[[nodiscard]] std::expected<void, std::string> writeMeshObj(const std::filesystem::path& path,
                                                            const Mesh& mesh);
// Binary STL: facet normals from the triangles' winding, coordinates in metres.
[[nodiscard]] std::expected<void, std::string> writeMeshStl(const std::filesystem::path& path,
                                                            const Mesh& mesh);

}  // namespace smx::scan
