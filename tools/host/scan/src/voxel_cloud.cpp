#include "voxel_cloud.hpp"

#include <cmath>

namespace smx::scan::detail {
namespace {

// 21 bits per axis: ±1 million voxels, ±2 km at 2 mm.
constexpr std::int64_t kHalfRange = std::int64_t{1} << 20;
constexpr std::uint64_t kMask = (std::uint64_t{1} << 21U) - 1U;

}  // namespace

std::uint64_t VoxelCloud::key(const Eigen::Vector3d& p) const {
  std::uint64_t k = 0;
  for (Eigen::Index i = 0; i < 3; ++i) {
    const auto cell = static_cast<std::int64_t>(std::floor(p[i] / voxelM_)) + kHalfRange;
    k = (k << 21U) | (static_cast<std::uint64_t>(cell) & kMask);
  }
  return k;
}

void VoxelCloud::add(const Cloud& cloud) {
  const bool normals = cloud.normals.size() == cloud.points.size();
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    Sum& s = voxels_[key(cloud.points[i])];
    s.point += cloud.points[i];
    if (normals) {
      s.normal += cloud.normals[i];
    }
    s.count += 1.0;
  }
}

Cloud VoxelCloud::cloud() const {
  Cloud out;
  out.points.reserve(voxels_.size());
  out.normals.reserve(voxels_.size());
  for (const auto& [k, s] : voxels_) {
    const double n = s.normal.norm();
    out.points.emplace_back(s.point / s.count);
    out.normals.push_back(n > 0 ? Eigen::Vector3d(s.normal / n) : Eigen::Vector3d::UnitZ());
  }
  return out;
}

Cloud VoxelCloud::visible(const Eigen::Vector3d& centre, const Eigen::Vector3d& forward,
                          double maxAngleRad, double maxDistanceM) const {
  Cloud out;
  const double cosMax = std::cos(maxAngleRad);
  for (const auto& [k, s] : voxels_) {
    const Eigen::Vector3d p = s.point / s.count;
    const Eigen::Vector3d ray = p - centre;
    const double distance = ray.norm();
    const double n = s.normal.norm();
    if (!(distance > 0) || distance > maxDistanceM || forward.dot(ray) < cosMax * distance ||
        !(n > 0) || s.normal.dot(ray) > 0) {
      continue;
    }
    out.points.push_back(p);
    out.normals.emplace_back(s.normal / n);
  }
  return out;
}

}  // namespace smx::scan::detail
