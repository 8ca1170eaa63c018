#pragma once

#include <array>
#include <expected>
#include <string>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/rig.hpp"
#include "smx/health/camera_depths.hpp"
#include "smx/health/disagreement.hpp"

// Which of two projectors seen by one camera moved, from the shape of their disagreement
// (docs/health-check.md): each projector's six small pose changes (1 mm along, 0.2° about each of
// its axes) are re-triangulated from its decoded stripes, giving per block how each moves that
// projector's depth; the best linear combination of one projector's six is fitted to the block
// medians of the disagreement. A projector whose fit leaves at most kDecisiveRatio of the other's
// residual is named. Host code.
namespace smx::health {

inline constexpr double kDecisiveRatio = 0.5;

struct Attribution {
  std::array<double, 2> residualMm{};  // RMS left by the fit of projector, of otherProjector
  int named = -1;                      // 0: projector, 1: otherProjector, −1: undecided
};

// `disagreement` is depth(projector) − depth(otherProjector) on depths.camera.
[[nodiscard]] std::expected<Attribution, std::string> attributeByShape(
    const algo::Rig& rig, const CameraDepths& depths, int projector, int otherProjector,
    const Disagreement& disagreement, const algo::PipelineOptions& options, int blockPx);

}  // namespace smx::health
