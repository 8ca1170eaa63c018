#pragma once

#include <optional>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/algo/range_image.hpp"
#include "smx/algo/rig.hpp"
#include "smx/sim/ply_io.hpp"

// Range images as point clouds: host side, double precision.
namespace smx::host {

// The points of a camera's range image in world coordinates, metres: pixel (x, y) with z ≠ 0 is
// z·(x_n, y_n, 1) in the camera frame ((x_n, y_n) its undistorted normalised coordinates), then
// Rᵀ·(p − t). Coloured from `colours` (the camera image) when given, else grey.
[[nodiscard]] std::vector<sim::PlyPoint> depthToWorldPoints(
    const algo::Camera& camera, algo::ConstDepthPlane depth, double depthUnitM,
    std::optional<algo::ConstRgbView> colours = std::nullopt);

}  // namespace smx::host
