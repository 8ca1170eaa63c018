#include "smx/scan/watertight.hpp"

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

#include <algorithm>
#include <cmath>

#include "open3d_bridge.hpp"

namespace smx::scan {

std::expected<Mesh, std::string> watertightMesh(const Cloud& cloud,
                                                const WatertightOptions& options) {
  if (cloud.size() < 10 || cloud.normals.size() != cloud.size()) {
    return std::unexpected("a watertight mesh needs at least 10 points with normals");
  }
  if (!std::isfinite(options.voxelM) || options.voxelM <= 0 || !std::isfinite(options.holeMaxM) ||
      options.holeMaxM < 0) {
    return std::unexpected("the voxel must be positive and the largest hole not negative");
  }
  const auto input = detail::toOpen3d(cloud);
  // The octree's finest cell about the model's voxel: depth = log2(extent / voxel).
  const double extent = (input->GetMaxBound() - input->GetMinBound()).maxCoeff();
  const double cells = std::max(extent / options.voxelM, 2.0);
  const auto depth = static_cast<std::size_t>(std::clamp(std::ceil(std::log2(cells)), 5.0, 11.0));
  auto [poisson, densities] =
      open3d::geometry::TriangleMesh::CreateFromPointCloudPoisson(*input, depth);
  (void)densities;  // the distance rule below replaces a density quantile: it has a unit

  // Keep a vertex when an input point lies within holeMax/2: the middle of a hole of diameter d
  // is d/2 from its rim, so holes up to holeMax are closed and larger ones stay open.
  const open3d::geometry::KDTreeFlann tree(*input);
  const double keepM = std::max(options.holeMaxM / 2, options.voxelM);
  const bool coloured = input->HasColors();
  std::vector<bool> removed(poisson->vertices_.size(), false);
  poisson->vertex_colors_.assign(poisson->vertices_.size(), Eigen::Vector3d::Constant(0.7));
  std::vector<int> index(1);
  std::vector<double> distance2(1);
  for (std::size_t i = 0; i < poisson->vertices_.size(); ++i) {
    if (tree.SearchKNN(poisson->vertices_[i], 1, index, distance2) < 1) {
      removed[i] = true;
      continue;
    }
    removed[i] = distance2[0] > keepM * keepM;
    if (coloured) {
      poisson->vertex_colors_[i] = input->colors_[static_cast<std::size_t>(index[0])];
    }
  }
  poisson->RemoveVerticesByMask(removed);
  poisson->RemoveUnreferencedVertices();
  poisson->ComputeVertexNormals();
  return detail::fromOpen3d(*poisson);
}

}  // namespace smx::scan
