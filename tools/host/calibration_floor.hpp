#pragma once

#include <filesystem>

#include "smx/algo/rig.hpp"

// What the captures' noise alone leaves (docs/calibration-results.md): the residuals of the real
// rig and the true target poses (DIR/truth/poses.json of `stripemux sim --calibration`) against
// what the calibration measures in the same images, the corners and the decoded stripes. No
// estimate of the rig can fit its data much better than the truth does, so these are the floor
// of the fit's residual figures.
namespace smx::host {

struct ResidualFloor {
  double cameraRmsPx = 0;     // detected corners against the true projections, largest camera
  double projectorRmsPx = 0;  // decoded stripes against the true ones, largest projector
};

// Throws std::runtime_error naming the file when the captures or their truth cannot be read.
[[nodiscard]] ResidualFloor truthResiduals(const std::filesystem::path& captures,
                                           const algo::Rig& real);

}  // namespace smx::host
