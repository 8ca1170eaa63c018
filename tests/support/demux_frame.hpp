#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "smx/algo/arena.hpp"
#include "smx/algo/demux.hpp"
#include "smx/eval/boundary_eval.hpp"
#include "smx/eval/sim_frame.hpp"

// Test support: a rendered frame through orientation demultiplexing, and the regions the
// accuracy tests score in.
namespace smx::test {

// Predictions for a surface at 0.75 m while the named scenes stand at 0.9 m and beyond, so what
// the tests measure is the estimator's direction, not the calibration's.
inline constexpr double kTestNominalDepthM = 0.75;

struct DemuxedFrame {
  std::vector<std::byte> memory;
  std::unique_ptr<algo::Arena> arena;
  std::unique_ptr<algo::Demultiplexer> demux;
};

// Runs camera 0 of the frame's rig; throws std::runtime_error naming the step that failed.
[[nodiscard]] std::unique_ptr<DemuxedFrame> demultiplex(const eval::SimFrame& frame,
                                                        const algo::DemuxParams& params = {},
                                                        double nominalDepthM = kTestNominalDepthM);

// The band along the image's edges where the demultiplexer finds no boundaries by construction:
// the 5-tap filters and the samples one pixel either side of a boundary need 4 px around it.
inline constexpr int kImageMarginPx = 4;

// Pixels lit by exactly `patterns` projectors, projector among them, 3 px inside that region and
// away from depth jumps over 2 %, outside the image's margin band.
[[nodiscard]] eval::Mask regionLitBy(const eval::SimFrame& frame, int projector, int patterns);

}  // namespace smx::test
