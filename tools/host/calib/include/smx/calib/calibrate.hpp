#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/calib/camera_calibration.hpp"
#include "smx/calib/joint_refinement.hpp"
#include "smx/calib/projector_calibration.hpp"

// `stripemux calibrate`: a rig from captures of a printed target (docs/calibration.md).
namespace smx::calib {

// Reprojection and stripe residuals above these make the verdict "check" rather than "good":
// a sharp, flat target fits to a small fraction of a pixel.
inline constexpr double kGoodCameraRmsPx = 0.5;
inline constexpr double kGoodProjectorRmsPx = 0.5;
// A projector whose stripes fit worse than this did not solve: its frames contradict each other
// (moved between poses, or another projector's frames), and its geometry would be wrong.
inline constexpr double kFailProjectorRmsPx = 2.0;

struct Calibration {
  algo::Rig rig;  // the nominal's ids, sizes and patterns; the calibrated geometry
  std::vector<CameraFit> cameras;
  std::vector<ProjectorFit> projectors;
  std::vector<TargetPose> targets;  // per pose of the set (known = placed)
  JointFigures joint;
  std::vector<std::string> notes;  // poses or files left out, and why
  std::string verdict;             // "good", or "check: …" naming what to look at
};

// Calibrates every camera and projector of `nominal` from the capture set in `dir`. An error
// names the pose, device or file and what to do, or says that the solve failed; nothing is
// solved halfway.
[[nodiscard]] std::expected<Calibration, std::string> calibrate(const algo::Rig& nominal,
                                                                const std::filesystem::path& dir);

}  // namespace smx::calib
