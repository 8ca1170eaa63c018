#include "open3d_bridge.hpp"

#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

namespace smx::scan::detail {

std::shared_ptr<open3d::geometry::PointCloud> toOpen3d(const Cloud& cloud) {
  auto out = std::make_shared<open3d::geometry::PointCloud>();
  out->points_ = cloud.points;
  if (cloud.normals.size() == cloud.points.size()) {
    out->normals_ = cloud.normals;
  }
  if (cloud.colours.size() == cloud.points.size()) {
    out->colors_ = cloud.colours;
  }
  return out;
}

Cloud fromOpen3d(const open3d::geometry::PointCloud& cloud) {
  Cloud out;
  out.points = cloud.points_;
  if (cloud.HasNormals()) {
    out.normals = cloud.normals_;
  }
  if (cloud.HasColors()) {
    out.colours = cloud.colors_;
  }
  return out;
}

Mesh fromOpen3d(const open3d::geometry::TriangleMesh& mesh) {
  Mesh out;
  out.vertices = mesh.vertices_;
  if (mesh.HasVertexNormals()) {
    out.normals = mesh.vertex_normals_;
  }
  if (mesh.HasVertexColors()) {
    out.colours = mesh.vertex_colors_;
  }
  out.triangles = mesh.triangles_;
  return out;
}

}  // namespace smx::scan::detail
