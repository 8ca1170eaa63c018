#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "smx/algo/arena.hpp"
#include "smx/algo/camera_pipeline.hpp"
#include "smx/eval/boundary_eval.hpp"
#include "smx/eval/depth_eval.hpp"
#include "smx/eval/sim_frame.hpp"

// One rendered camera frame through the firmware's per-camera pipeline, scored against the
// simulator's truth: the figures of `stripemux eval` (docs/results.md) and of the decode accuracy
// tests. Host code; throws std::runtime_error naming the step that failed.
namespace smx::eval {

// Where the pipelines predict the pattern directions: nearer than the named scenes (0.9 m and
// beyond), so what is measured is the estimator's direction, not the calibration's.
inline constexpr double kEvalNominalDepthM = 0.75;

// A camera pipeline with the arena it lives in.
struct PipelineRun {
  std::vector<std::byte> memory;
  std::unique_ptr<algo::Arena> arena;
  std::unique_ptr<algo::CameraPipeline> pipeline;
};

[[nodiscard]] algo::PipelineOptions evalPipelineOptions();
// Created, not run: callers time or instrument run() themselves.
[[nodiscard]] std::unique_ptr<PipelineRun> makePipeline(const algo::Rig& rig, int camera,
                                                        const algo::PipelineOptions& options);
// makePipeline + run() on the frame's image.
[[nodiscard]] std::unique_ptr<PipelineRun> runPipeline(
    const SimFrame& frame, int camera,
    const algo::PipelineOptions& options = evalPipelineOptions());

// Pixels lit by at least (or exactly) n projectors, restricted to `projector`'s lit pixels when
// projector ≥ 0; "smooth" keeps only pixels 3 px inside that region and away from depth jumps
// over 2 % (occlusion edges).
struct RegionSpec {
  int patterns = 1;
  bool exactly = false;
  bool smooth = false;
  int projector = -1;
};
[[nodiscard]] Mask litRegion(const SimFrame& frame, const RegionSpec& spec);

// The merged range image (disparity figures for the mean of the pairs' baselines) and one
// projector's range image, scored in a region.
[[nodiscard]] DepthScore scoreMerged(const SimFrame& frame, int camera,
                                     const algo::CameraPipeline& pipeline, const Mask& region);
[[nodiscard]] DepthScore scorePair(const SimFrame& frame, int camera,
                                   const algo::CameraPipeline& pipeline, int projector,
                                   const Mask& region);

struct FrameFigures {
  DepthScore mergedAll;            // lit by ≥ 1, every pixel (gross errors at edges count)
  DepthScore mergedSmooth;         // lit by ≥ 1, smooth interior (completeness)
  DepthScore merged2;              // lit by exactly 2, smooth interior
  DepthScore merged3;              // lit by exactly 3, smooth interior
  std::vector<DepthScore> pairs;   // each projector where it lights the surface, smooth
  std::vector<DepthScore> pairs2;  // each projector where it and exactly 1 other light, smooth
  std::vector<DepthScore> pairs3;  // each projector where exactly 3 light, smooth
};
[[nodiscard]] FrameFigures measureFrame(const SimFrame& frame, int camera,
                                        const algo::CameraPipeline& pipeline);

// A depth-quality tool's flat-target figures: a least-squares plane through the camera-frame
// points of the valid pixels in the region; RMS of their distances to it, and the share of the
// region's pixels that have depth.
struct PlaneFit {
  int points = 0;
  int regionPixels = 0;
  double rmsMm = 0;
  double fillRate = 0;
};
[[nodiscard]] PlaneFit fitPlane(const algo::Camera& camera, algo::ConstDepthPlane depth,
                                algo::ImageView<const std::uint8_t> region,
                                double depthUnitM = algo::kDefaultDepthUnitM);

}  // namespace smx::eval
