#pragma once

#include <Eigen/Core>
#include <expected>
#include <optional>
#include <string>
#include <vector>

#include "smx/scan/points.hpp"
#include "smx/scan/range_view.hpp"

// Registration of one cloud to another (docs/scanning.md): point-to-plane ICP from an initial
// pose, coarse to fine with a robust kernel, and a global alignment (FPFH + RANSAC) for when
// no initial pose is known (relocalisation). Host only.
namespace smx::scan {

struct IcpOptions {
  // Voxel sizes of the levels, coarse to fine; both clouds are downsampled to each in turn.
  std::vector<double> levelVoxelsM = {0.004, 0.002, 0.001};
  // A correspondence is a pair closer than this many voxels of the level.
  double maxDistanceVoxels = 3.0;
  // Tukey kernel width in voxels of the level: residuals beyond it carry no weight.
  double kernelVoxels = 2.0;
  int iterationsPerLevel = 30;
};

struct Registration {
  Pose pose = Pose::Identity();  // source → target: target ≈ pose · source
  double fitness = 0.0;          // share of source points with a correspondence (finest level)
  double inlierRmseM = 0.0;      // RMS distance of those correspondences, metres
  // Information matrix of the pose (Open3D order: rotation, then translation), for a pose graph.
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
};

// Point-to-plane ICP of `source` onto `target` (which needs normals) starting at `initial`.
// Errors: an empty cloud, a target without normals, bad options. A registration that converged
// to little overlap is not an error: judge `fitness`.
[[nodiscard]] std::expected<Registration, std::string> registerIcp(const Cloud& source,
                                                                   const Cloud& target,
                                                                   const Pose& initial,
                                                                   const IcpOptions& options = {});

struct GlobalOptions {
  double voxelM = 0.004;    // features are computed on the clouds downsampled to this
  double minFitness = 0.3;  // below this after refinement the alignment is "not found"
  int maxIterations = 100000;
  double confidence = 0.999;
  unsigned seed = 1;  // RANSAC's random choices, for repeatable runs
};

// FPFH features matched with RANSAC, then refined by registerIcp: source → target without an
// initial pose. nullopt when no alignment reaches options.minFitness (not found).
[[nodiscard]] std::optional<Registration> alignGlobal(const Cloud& source, const Cloud& target,
                                                      const GlobalOptions& options = {},
                                                      const IcpOptions& refine = {});

}  // namespace smx::scan
