#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>

#include "smx/scan/points.hpp"

// A point cloud fused on a voxel grid: every voxel keeps the sums of the points and normals that
// fell in it and their count, so that the cloud is the running mean of all of them (a frame
// added later weighs as much as an earlier one, unlike repeated downsampling of a merged cloud).
namespace smx::scan::detail {

class VoxelCloud {
 public:
  explicit VoxelCloud(double voxelM) : voxelM_(voxelM) {}

  // Adds points with normals (normals may be empty: the voxel's normal is then unset).
  void add(const Cloud& cloud);
  void clear() { voxels_.clear(); }
  [[nodiscard]] std::size_t size() const { return voxels_.size(); }

  // Every voxel's mean point and unit mean normal.
  [[nodiscard]] Cloud cloud() const;

  // The voxels a camera at `centre` looking along `forward` (unit) sees: within `maxAngleRad` of
  // its axis, at most `maxDistanceM` away, with normals facing it.
  [[nodiscard]] Cloud visible(const Eigen::Vector3d& centre, const Eigen::Vector3d& forward,
                              double maxAngleRad, double maxDistanceM) const;

 private:
  struct Sum {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    double count = 0.0;
  };
  struct KeyHash {
    std::size_t operator()(std::uint64_t k) const { return k * 0x9E3779B97F4A7C15ULL >> 20U; }
  };

  [[nodiscard]] std::uint64_t key(const Eigen::Vector3d& p) const;

  double voxelM_;
  std::unordered_map<std::uint64_t, Sum, KeyHash> voxels_;
};

}  // namespace smx::scan::detail
