#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <expected>
#include <optional>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/calib/camera_calibration.hpp"
#include "smx/calib/capture_set.hpp"

// The projectors' part of calibration. A projector here shows one fixed stripe pattern, so it
// cannot be treated as an inverse camera: each stripe boundary is a surface through the
// projector's centre and a point seen on it tells one projector coordinate, the one across the
// stripes. The stripe coordinate decoded at each camera pixel of the target, with the target's
// plane from the cameras' fit, gives (world point, stripe coordinate) samples; the projector's
// pose, focal length, principal point across the stripes and lens are fitted to them (Ceres,
// robust loss, outliers removed).
//
// What the samples cannot tell is kept at the nominal rig and said so: the principal point
// along the stripes, the focal length along them (tied to the other, square pixels) and how far
// along the stripes' direction the centre lies (every boundary surface contains that line).
namespace smx::calib {

struct StripeSample {
  double x = 0.0;  // camera pixel
  double y = 0.0;
  Eigen::Vector3d point;  // world, on the target
  double stripe = 0.0;    // decoded stripe coordinate (algo::stripeCoordinate units)
  std::size_t pose = 0;
  std::size_t camera = 0;
};

struct PoseResidual {
  std::string pose;
  int samples = 0;     // kept
  int outliers = 0;    // removed
  double rmsPx = 0.0;  // projector pixels across the stripes
  double rmsMm = 0.0;  // the same as a distance across the boundary surface at the sample
};

struct ProjectorFit {
  algo::Projector projector;
  double rmsPx = 0.0;
  double rmsMm = 0.0;
  int samples = 0;
  int outliers = 0;
  std::vector<PoseResidual> poses;
  std::vector<std::string> fixedAtNominal;
  std::vector<StripeSample> inliers;  // the samples the fit kept
};

// Where camera pixel (x, y) sees the target's plane in `pose`, world; nullopt when the ray
// misses it.
[[nodiscard]] std::optional<Eigen::Vector3d> targetPoint(const algo::Camera& camera,
                                                         const TargetPose& pose, double x,
                                                         double y);

// The decoded stripe coordinates of projector `projector` of `nominal` over the set's poses and
// cameras. Poses the target was not placed in, or without that projector's frame, are skipped
// (notes say which).
[[nodiscard]] std::expected<std::vector<StripeSample>, std::string> stripeSamples(
    const CaptureSet& set, const CamerasFit& cameras, const algo::Rig& nominal,
    std::size_t projector, std::vector<std::string>& notes);

// The sample's residual across the stripes in projector pixels: the stripe coordinate
// `projector` casts on the sample's point minus the decoded one.
[[nodiscard]] double stripeResidualPx(const algo::Projector& projector, const StripeSample& sample);

// Sets fit's residual figures (overall and per pose of `set`) from fit.projector and
// fit.inliers; `all` are the samples before outliers were removed.
void measureResiduals(ProjectorFit& fit, const std::vector<StripeSample>& all,
                      const CaptureSet& set);

// Fits `nominal`'s pose and lens to the samples.
[[nodiscard]] std::expected<ProjectorFit, std::string> fitProjector(
    const algo::Projector& nominal, const std::vector<StripeSample>& samples,
    const CaptureSet& set);

}  // namespace smx::calib
