#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "calibration_floor.hpp"
#include "smx/algo/rig.hpp"
#include "smx/eval/depth_eval.hpp"

// `stripemux eval --only calibration` (docs/calibration-results.md): for each example rig, a
// "real" rig drawn near it (poses, lenses, projector distortion), simulated captures of the
// printed target with the realistic optics, the solve from the example rig as the nominal, and
// the result measured against the real rig: intrinsics, poses, the depth the calibrated rig
// would triangulate from exact stripes, and the named scenes decoded with each rig.
namespace smx::host {

struct CalibrationEvalOptions {
  std::vector<std::string> rigs = {"rig_2proj_1cam.json", "rig_2proj_2cam.json",
                                   "rig_3proj_1cam.json", "rig_3proj_2cam.json"};
  std::vector<std::string> scenes;  // named scenes decoded with both rigs; empty: all
  // Each rig is solved from this many poses of the target: the 12, and twice that, which
  // shows how much of the error is the few views' uncertainty.
  std::vector<int> poseCounts = {12, 24};
  std::uint64_t seed = 1;
  std::filesystem::path work;  // captures are rendered here (kept for inspection)
  std::function<void(const std::string&)> progress;
};

// A device of the calibrated rig against the real one.
struct DeviceError {
  std::string id;
  double focalPx = 0;        // |fx − fx_true| (projectors: along the encoding axis)
  double principalPx = 0;    // principal point (projectors: along the encoding axis)
  double centreMm = 0;       // centre; projectors: perpendicular to the stripes' direction
  double centreAlongMm = 0;  // projectors: along the stripes' direction (not observable)
  double axesDeg = 0;        // largest angle between a true and a calibrated device axis
  // Projectors: depth the calibrated rig triangulates from exact stripe coordinates, minus the
  // true depth, over cam0's image at 0.6–1.2 m: RMS and largest, mm.
  double depthRmsMm = 0;
  double depthMeanMm = 0;  // signed: a scale error shows here
  double depthMaxMm = 0;
};

struct SceneDepth {
  std::string scene;
  eval::DepthScore real;        // decoded with the real rig
  eval::DepthScore calibrated;  // the same images, decoded with the calibrated rig
};

struct CalibrationCase {
  std::string rig;
  int poses = 0;
  std::string verdict;
  std::string failure;        // the solve's error; empty when it succeeded
  double cameraRmsPx = 0;     // largest over the cameras
  double projectorRmsPx = 0;  // largest over the projectors
  ResidualFloor floor;        // the same figures for the real rig: the noise alone
  std::vector<DeviceError> cameras;
  std::vector<DeviceError> projectors;
  std::vector<SceneDepth> scenes;
  double solveSeconds = 0;
};

// The real rig of a case: `nominal` with every device moved and turned a little (the first
// camera stays the world frame), focal lengths and principal points off, and lens distortion on
// cameras and projectors, drawn from `seed`.
[[nodiscard]] algo::Rig drawRealRig(const algo::Rig& nominal, std::uint64_t seed);

// Geometric depth error of `calibrated` against `real` for projector p (DeviceError's depth
// figures): exact stripe coordinates of points in front of the first camera, triangulated with
// each rig.
void measureStripeDepth(const algo::Rig& real, const algo::Rig& calibrated, std::size_t p,
                        DeviceError& error);

// Renders `poses` calibration captures of the real rig with the realistic optics into
// dir/captures (dir/real.json beside them) and returns that folder. Throws when it fails.
[[nodiscard]] std::filesystem::path renderCalibrationCaptures(const algo::Rig& real, int poses,
                                                              std::uint64_t seed,
                                                              const std::filesystem::path& dir);

// `scene` rendered with the real rig, decoded with each rig and scored.
[[nodiscard]] SceneDepth decodeWithBoth(const algo::Rig& real, const algo::Rig& calibrated,
                                        const std::string& scene, std::uint64_t seed);

[[nodiscard]] std::vector<CalibrationCase> runCalibrationEval(
    const CalibrationEvalOptions& options);
[[nodiscard]] std::string calibrationMarkdown(const std::vector<CalibrationCase>& cases,
                                              const std::string& command);

}  // namespace smx::host
