#pragma once

#include <memory>

#include "smx/scan/fusion.hpp"
#include "smx/scan/points.hpp"

// Our clouds and meshes to Open3D's and back, for the .cpp files that call Open3D (only they
// include its headers).
namespace open3d::geometry {
class PointCloud;
class TriangleMesh;
}  // namespace open3d::geometry

namespace smx::scan::detail {

[[nodiscard]] std::shared_ptr<open3d::geometry::PointCloud> toOpen3d(const Cloud& cloud);
[[nodiscard]] Cloud fromOpen3d(const open3d::geometry::PointCloud& cloud);
[[nodiscard]] Mesh fromOpen3d(const open3d::geometry::TriangleMesh& mesh);

}  // namespace smx::scan::detail
