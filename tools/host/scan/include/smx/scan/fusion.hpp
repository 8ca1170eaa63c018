#pragma once

#include <Eigen/Core>
#include <expected>
#include <memory>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/scan/points.hpp"
#include "smx/scan/range_view.hpp"

// Fusion of range views into one surface: a truncated signed distance volume (Open3D's
// ScalableTSDFVolume) and its extraction as points or triangles (docs/scanning.md). Host only.
namespace smx::scan {

struct Mesh {
  std::vector<Eigen::Vector3d> vertices{};
  std::vector<Eigen::Vector3d> normals{};  // per vertex, empty or as long as vertices
  std::vector<Eigen::Vector3d> colours{};  // per vertex RGB in [0, 1], empty or as long
  std::vector<Eigen::Vector3i> triangles{};
};

struct FusionOptions {
  double voxelM = 0.001;       // e.g. 1 mm for a 15-cm object
  double truncationM = 0.004;  // the signed distance is cut at ± this (3–5 voxels)
  double maxDepthM = 3.0;      // depths beyond are not integrated
};

// A TSDF in the model frame. Each camera's depth is resampled into an undistorted pinhole image
// of the same K by nearest neighbour (depth is never interpolated across edges) before Open3D
// integrates it.
class Tsdf {
 public:
  // Errors: options out of range, a rig without cameras.
  [[nodiscard]] static std::expected<Tsdf, std::string> create(const algo::Rig& rig,
                                                               const FusionOptions& options = {});
  Tsdf(Tsdf&&) noexcept;
  Tsdf& operator=(Tsdf&&) noexcept;
  Tsdf(const Tsdf&) = delete;
  Tsdf& operator=(const Tsdf&) = delete;
  ~Tsdf();

  // Integrates every camera of `view` (rig order) with the rig at `pose` (rig → model).
  // Errors: a camera whose image size is not the rig's.
  [[nodiscard]] std::expected<void, std::string> integrate(const RangeView& view, const Pose& pose);

  // The zero crossing as points with normals and colours, and as a triangle mesh (marching
  // cubes) with vertex normals and colours.
  [[nodiscard]] Cloud extractCloud() const;
  [[nodiscard]] Mesh extractMesh() const;

 private:
  struct Impl;
  explicit Tsdf(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_{};
};

}  // namespace smx::scan
