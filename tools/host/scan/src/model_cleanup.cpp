#include "smx/scan/model_cleanup.hpp"

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

#include <algorithm>
#include <tuple>
#include <vector>

#include "open3d_bridge.hpp"

namespace smx::scan {

CleanupReport removeLoosePieces(Mesh& mesh, Cloud& model, double minShare, double voxelM) {
  CleanupReport report;
  if (mesh.triangles.empty()) {
    return report;
  }
  open3d::geometry::TriangleMesh o3d;
  o3d.vertices_ = mesh.vertices;
  o3d.vertex_normals_ = mesh.normals;
  o3d.vertex_colors_ = mesh.colours;
  o3d.triangles_ = mesh.triangles;
  const auto clusters = o3d.ClusterConnectedTriangles();
  const std::vector<int>& clusterOf = std::get<0>(clusters);
  const std::vector<std::size_t>& trianglesIn = std::get<1>(clusters);
  if (trianglesIn.empty()) {
    return report;
  }
  const std::size_t largest = std::ranges::max(trianglesIn);
  const auto keep = [&](int cluster) {
    return static_cast<double>(trianglesIn[static_cast<std::size_t>(cluster)]) >=
           minShare * static_cast<double>(largest);
  };
  for (std::size_t c = 0; c < trianglesIn.size(); ++c) {
    if (!keep(static_cast<int>(c))) {
      ++report.piecesRemoved;
      report.trianglesRemoved += trianglesIn[c];
    }
  }
  if (report.piecesRemoved == 0) {
    return report;
  }
  std::vector<bool> remove(clusterOf.size());
  for (std::size_t t = 0; t < clusterOf.size(); ++t) {
    remove[t] = !keep(clusterOf[t]);
  }
  o3d.RemoveTrianglesByMask(remove);
  o3d.RemoveUnreferencedVertices();
  mesh = detail::fromOpen3d(o3d);

  open3d::geometry::PointCloud kept;
  kept.points_ = mesh.vertices;
  const open3d::geometry::KDTreeFlann tree(kept);
  const double reach2 = 4.0 * voxelM * voxelM;
  std::vector<int> index(1);
  std::vector<double> distance2(1);
  Cloud out;
  for (std::size_t i = 0; i < model.points.size(); ++i) {
    if (tree.SearchKNN(model.points[i], 1, index, distance2) > 0 && distance2[0] <= reach2) {
      out.points.push_back(model.points[i]);
      if (!model.normals.empty()) {
        out.normals.push_back(model.normals[i]);
      }
      if (!model.colours.empty()) {
        out.colours.push_back(model.colours[i]);
      }
    }
  }
  report.pointsRemoved = model.points.size() - out.points.size();
  model = std::move(out);
  return report;
}

}  // namespace smx::scan
