#pragma once

#include <open3d/geometry/TriangleMesh.h>

#include <Eigen/Geometry>
#include <vector>

#include "smx/sim/scene.hpp"

// The simulator's objects as triangles, and a fused mesh measured against them.
namespace smx::scan_eval::detail {

// The realism options of the renderer at the middle of the ranges the realism suite draws from
// (docs/simulator.md): projector black level 1 %, display gamma 2.1, projector and camera
// defocus 0.6 and 0.4 px, response gamma 1.6, vignetting 20 %, an RGGB Bayer mosaic.
void addRealism(sim::Scene& scene);

// `object`'s surface, moved by `to` after its pose (world → model frame).
[[nodiscard]] open3d::geometry::TriangleMesh objectSurface(
    const sim::Object& object, const Eigen::Isometry3d& to = Eigen::Isometry3d::Identity());

struct DistanceStats {
  double meanMm = 0.0;
  double p95Mm = 0.0;
};

// Every vertex's distance to the surface.
[[nodiscard]] DistanceStats distancesToSurface(const std::vector<Eigen::Vector3d>& vertices,
                                               const open3d::geometry::TriangleMesh& surface);

// For each of `points`, 1 when it lies within `distanceM` of the surface.
[[nodiscard]] std::vector<char> withinMask(const std::vector<Eigen::Vector3d>& points,
                                           const open3d::geometry::TriangleMesh& surface,
                                           double distanceM);

// How many of `points` lie within `distanceM` of the surface.
[[nodiscard]] std::size_t countWithin(const std::vector<Eigen::Vector3d>& points,
                                      const open3d::geometry::TriangleMesh& surface,
                                      double distanceM);

}  // namespace smx::scan_eval::detail
