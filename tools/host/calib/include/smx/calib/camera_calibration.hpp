#pragma once

#include <Eigen/Core>
#include <array>
#include <expected>
#include <string>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/algo/rig.hpp"
#include "smx/calib/capture_set.hpp"

// The cameras' part of calibration (OpenCV calib3d): the target's corners in each projector-off
// frame, each camera's intrinsics and lens, the cameras' poses relative to the first camera
// (the world frame) and the target's pose in each capture.
namespace smx::calib {

// A capture set needs the target found in at least this many poses per camera: the 9 intrinsic
// and lens parameters and 6 per pose need several tilts to separate focal length from distance.
inline constexpr int kMinPoses = 6;

struct PoseUse {
  std::string pose;
  bool used = false;
  double rmsPx = 0.0;  // reprojection RMS of its corners (when used)
  std::string note;    // why not used, or empty
};

struct CameraFit {
  algo::Camera camera;
  double rmsPx = 0.0;  // over the corners of the poses used
  // Standard deviations of fx, fy, cx, cy (px) and k1, k2, p1, p2, k3 as the fit estimates them
  // from the measurements' scatter: how well the data determined each.
  std::array<double, 9> sd{};
  // The standard deviation of the depth scale that the focal lengths' uncertainty implies, in mm
  // at 1 m. Set by the joint refinement; 0 before it.
  double depthScaleSdMm = 0.0;
  std::vector<PoseUse> poses;
  std::vector<std::string> fixedAtNominal;  // parameters the data did not determine
  // Per pose of the set: the target's corners found in this camera, in target order; empty where
  // the pose is not used.
  std::vector<std::vector<std::array<double, 2>>> corners;
};

// Target → world: X = R · x + t.
struct TargetPose {
  bool known = false;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
};

struct CamerasFit {
  std::vector<CameraFit> cameras;
  std::vector<TargetPose> targets;  // per pose of the set
  std::vector<std::string> notes;
};

// Corners of `target` in an 8-bit RGB image, in target order (innerCorners()); empty when the
// whole target is not in view.
[[nodiscard]] std::vector<std::array<double, 2>> findTargetCorners(const Target& target,
                                                                   const algo::ConstRgbView& image);

// Calibrates every camera of `nominal` from the set's projector-off frames; the nominal K is the
// starting guess, its ids and sizes are kept. Errors say which camera and pose and what to do.
[[nodiscard]] std::expected<CamerasFit, std::string> calibrateCameras(const CaptureSet& set,
                                                                      const algo::Rig& nominal);

}  // namespace smx::calib
