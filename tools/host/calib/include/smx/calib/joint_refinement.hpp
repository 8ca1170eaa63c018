#pragma once

#include <expected>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/calib/camera_calibration.hpp"
#include "smx/calib/capture_set.hpp"
#include "smx/calib/projector_calibration.hpp"

// The last step of calibration: every camera, target pose and projector refined together
// (bundle adjustment, Ceres) over the corners and the stripe samples at once. The cameras' own
// fit leaves their focal length and principal point as uncertain as a dozen views of a board
// allow; the projectors see the same boards from elsewhere, and their stripes on them, tens of
// thousands of points, pin the target poses and through them the cameras.
namespace smx::calib {

struct JointFigures {
  double cornerSigmaPx = 0.0;  // the weights: each kind's scatter in its own fit
  double stripeSigmaPx = 0.0;
  int iterations = 0;
  bool converged = false;
};

// Refines `cameras` (intrinsics, lenses, poses, target poses) and `projectors` in place, starting
// from their separate fits, and recomputes their residual figures. `samples[p]` are projector
// p's samples before outliers were removed (for its outlier count).
[[nodiscard]] std::expected<JointFigures, std::string> refineJointly(
    const CaptureSet& set, const algo::Rig& nominal, CamerasFit& cameras,
    std::vector<ProjectorFit>& projectors, const std::vector<std::vector<StripeSample>>& samples);

}  // namespace smx::calib
