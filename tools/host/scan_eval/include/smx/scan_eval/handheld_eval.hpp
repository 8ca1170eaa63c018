#pragma once

#include <cstdint>
#include <functional>
#include <string>

// The hand-held scan's figures (`stripemux eval --only scan`, docs/scan-results.md): a named scene
// with a hand-held trajectory (scene.json "handheld") rendered frame by frame with its motion
// blur and occlusion, decoded by the firmware's pipeline, tracked and fused as `stripemux scan
// --handheld` does, against the true trajectory and surface. Host code; throws
// std::runtime_error naming the step that failed.
namespace smx::scan_eval {

struct HandheldEvalOptions {
  std::string scene = "head_handheld";
  std::string rigFile = "rig_2proj_1cam.json";  // boards/sim/<rigFile>
  int frames = 300;
  double voxelM = 0.001;
  int supersampling = 0;
  std::uint64_t seed = 1;
  bool realism = true;  // the renderer's realism options (addRealism), as real optics have
  std::function<void(const std::string&)> progress{};
};

struct HandheldEvalResult {
  std::string scene;
  int frames = 0;
  int tracked = 0;  // tracking or relocalised
  int fused = 0;
  int lost = 0;
  int occluded = 0;          // frames the hand covered
  int occludedFused = 0;     // of them, fused (should be 0)
  int resumeFrame = -1;      // the first frame tracked again after the occlusion
  double resumeErrorMm = 0;  // its pose error: a jump shows here
  // Tracked frames' poses against the truth (relative to the first frame).
  double trajectoryRmsMm = 0.0;
  double trajectoryRmsDeg = 0.0;
  double driftMm = 0.0;  // the last frame's error: what a loop accumulates
  double driftDeg = 0.0;
  double meshMeanMm = 0.0;  // fused mesh vertices to the true surface
  double meshP95Mm = 0.0;
  double trackMsMean = 0.0;  // tracking time per frame on this machine
  double trackMsP95 = 0.0;
};

[[nodiscard]] HandheldEvalResult runHandheldEval(const HandheldEvalOptions& options);

}  // namespace smx::scan_eval
