#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

// How much a calibration's result depends on which poses happened to be captured
// (docs/calibration-results.md, "How much the poses leave to chance"): one real rig solved from
// many capture sets, each with its own target poses and noise, and the spread of the depth scale
// beside the uncertainty the solve itself reports. Host code; throws std::runtime_error naming
// the step that failed.
namespace smx::host {

struct SpreadOptions {
  std::string rig = "rig_2proj_1cam.json";  // boards/sim/<rig>; the real rig drawn near it
  std::vector<int> poseCounts = {12, 24};
  int sets = 8;  // capture sets per pose count
  std::uint64_t seed = 1;
  std::string scene = "plane";  // decoded with the real and each calibrated rig
  std::filesystem::path work;
  std::function<void(const std::string&)> progress;
};

struct SpreadRun {
  int poses = 0;
  std::uint64_t seed = 0;         // the capture set's
  std::string failure;            // the solve's error; empty when it succeeded
  double focalErrorPx = 0;        // cam0's fx, calibrated − real
  double predictedScaleSdMm = 0;  // the solve's own: cam0's depth scale sd, mm at 1 m
  double scaleErrorMm = 0;        // cam0's focal lengths' relative error, as mm at 1 m
  double stripeDepthMeanMm = 0;   // proj0's exact-stripe depth error, signed mean
  double sceneRatio = 0;          // the scene's RMSE, calibrated over real
};

[[nodiscard]] std::vector<SpreadRun> runCalibrationSpread(const SpreadOptions& options);
[[nodiscard]] std::string spreadMarkdown(const SpreadOptions& options,
                                         const std::vector<SpreadRun>& runs);

}  // namespace smx::host
