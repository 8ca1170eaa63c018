// The whole pipeline (demultiplexing, decoding, triangulation, merging) against the simulator's
// ground truth, per named scene (fixed seed, the paper's noise). Each case prints its figures;
// `decode_accuracy_test` alone prints the tables quoted in docs/decode.md.
//
// Targets (issue): completeness ≥ 95 % on smooth surfaces, ≥ 90 % where 2 patterns overlap,
// ≥ 80 % where 3 do; gross errors (|z − z_gt| > max(5 mm, 1 %)) ≤ 0.1 % of valid pixels; RMSE
// of the rest ≤ 0.1 px of equivalent disparity. Tests assert looser bounds where a target is not
// met yet and say so.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "alloc_counter.hpp"
#include "demux_frame.hpp"
#include "smx/algo/camera_pipeline.hpp"
#include "smx/eval/boundary_eval.hpp"
#include "smx/eval/depth_eval.hpp"
#include "smx/eval/frame_eval.hpp"
#include "smx/eval/sim_frame.hpp"

namespace smx::algo {
namespace {

std::unique_ptr<eval::PipelineRun> runCounted(const eval::SimFrame& f, int camera,
                                              const DecodeParams& decode = {}) {
  PipelineOptions options = eval::evalPipelineOptions();
  options.decode = decode;
  auto p = eval::makePipeline(f.rig, camera, options);
  const test::AllocationCounter counter;
  EXPECT_TRUE(p->pipeline->run(f.image.view()));
  EXPECT_EQ(counter.allocations(), 0U) << "the per-frame pipeline touched the heap";
  return p;
}

void print(const std::string& what, const eval::DepthScore& s) {
  std::printf(
      "%-34s %7d px | completeness %.4f | gross %.5f (%d) | rmse %.3f mm, %.4f px | mean %+.3f mm "
      "| phantom %d, outside %d (gross %d)\n",
      what.c_str(), s.regionPixels, s.completeness, s.grossRate, s.gross, s.rmseMm,
      s.rmsDisparityPx, s.meanErrorMm, s.phantom, s.validOutside, s.grossOutside);
}

using SceneFigures = eval::FrameFigures;

SceneFigures measure(const eval::SimFrame& f, const std::string& label, int camera = 0,
                     const DecodeParams& decode = {}) {
  const auto p = runCounted(f, camera, decode);
  const SceneFigures fig = eval::measureFrame(f, camera, *p->pipeline);
  print(label + " merged, lit by >= 1", fig.mergedAll);
  print(label + " merged, lit by >= 1, smooth", fig.mergedSmooth);
  if (fig.merged2.regionPixels > 0) {
    print(label + " merged, lit by 2, smooth", fig.merged2);
  }
  if (fig.merged3.regionPixels > 0) {
    print(label + " merged, lit by 3, smooth", fig.merged3);
  }
  for (std::size_t q = 0; q < fig.pairs.size(); ++q) {
    print(label + " proj" + std::to_string(q) + " alone, smooth", fig.pairs[q]);
  }
  return fig;
}

struct Bounds {
  double completenessSmooth;
  double completeness2;
  double completeness3;
  double grossRate;
  double rmsDisparityPx;
};

void expectWithin(const SceneFigures& fig, const Bounds& b, const std::string& what) {
  EXPECT_GT(fig.mergedSmooth.regionPixels, 10000) << what;
  EXPECT_GE(fig.mergedSmooth.completeness, b.completenessSmooth) << what;
  if (fig.merged2.regionPixels > 1000) {
    EXPECT_GE(fig.merged2.completeness, b.completeness2) << what;
  }
  if (fig.merged3.regionPixels > 1000) {
    EXPECT_GE(fig.merged3.completeness, b.completeness3) << what;
  }
  EXPECT_LE(fig.mergedAll.grossRate, b.grossRate) << what;
  EXPECT_LE(fig.mergedAll.rmsDisparityPx, b.rmsDisparityPx) << what;
  for (const auto& pair : fig.pairs) {
    EXPECT_LE(pair.grossRate, 5 * b.grossRate + 0.002) << what;
  }
}

// The targets; where a scene does not meet one yet its test asserts the measured level
// with a small margin (a ratchet) and says which. Gross errors are counted over every lit pixel
// (occlusion edges included), completeness over the smooth interior.
// The statue scene: a head at 0.9 m in front of a wall at 1.2 m (hal/sim/scenes/statue.json).
constexpr double kStatueBehindM = 1.15;

constexpr Bounds kTargets{0.95, 0.90, 0.80, 0.001, 0.1};

// The board: completeness and gross errors beat the targets. The disparity RMS meets the target
// with oblique patterns (three at 60°: 0.092 px; 70°: 0.100 px, asserted at 0.105) but not at 90°
// (0.133 px, ratchet 0.16): there the boundaries run along pixel rows and columns, every pixel of
// a curve has the same sub-pixel bias (docs/demux.md), and averaging along the curve cannot
// remove it.
constexpr Bounds kBoard{0.98, 0.98, 0.98, kTargets.grossRate / 2, 0.16};

TEST(DecodeAccuracy, PlaneTwoPatterns90Deg) {
  const auto f = eval::renderSimFrame({"rig_2proj_1cam.json", "plane"});
  expectWithin(measure(f, "plane 2 x 90deg"), kBoard, "plane 90deg");
}

// The two-camera rig's second camera, turned 15° towards the board. Its boundaries are as
// accurate as the first camera's (0.19 px RMS, measured with boundary_eval), but in its view
// the stripes cross the epipolar lines at a flatter angle, so the same position error is a
// larger depth error: 0.46 px of equivalent disparity per pair, 0.32 px merged (ratchet 0.35).
TEST(DecodeAccuracy, PlaneSecondCamera) {
  const auto f =
      eval::renderSimFrame({.rigFile = "rig_2proj_2cam.json", .scene = "plane", .camera = 1});
  Bounds bounds = kBoard;
  bounds.rmsDisparityPx = 0.35;
  expectWithin(measure(f, "plane cam1 of 2", 1), bounds, "plane cam1");
}

TEST(DecodeAccuracy, PlaneTwoPatterns70Deg) {
  auto rig = eval::loadExampleRig("rig_2proj_1cam.json");
  rig.projectors[1].pattern.angleDeg = 70.0;
  const auto f = eval::renderSimFrame(rig, eval::loadNamedScene("plane"));
  Bounds bounds = kBoard;
  bounds.rmsDisparityPx = 0.105;
  expectWithin(measure(f, "plane 2 x 70deg"), bounds, "plane 70deg");
}

TEST(DecodeAccuracy, PlaneThreePatterns60Deg) {
  const auto f = eval::renderSimFrame({"rig_3proj_1cam.json", "plane"});
  Bounds bounds = kBoard;
  bounds.rmsDisparityPx = kTargets.rmsDisparityPx;
  expectWithin(measure(f, "plane 3 x 60deg"), bounds, "plane 3 patterns");
}

// Curved and occluding scenes: completeness meets the target on smooth parts; gross errors
// (0.2–0.33 %, at grazing incidence and occlusion edges where a boundary curve is decoded to a
// wrong level) and the disparity RMS (0.15–0.18 px) do not yet (ratchets). The RGBCMY panel's
// smooth completeness is 89 %: where one projector meets a dark surface colour its pattern is
// lost (ratchet 0.87).
TEST(DecodeAccuracy, Sphere) {
  const auto f = eval::renderSimFrame({"rig_2proj_1cam.json", "sphere"});
  expectWithin(measure(f, "sphere"), {0.96, 0.96, 0, 0.0032, 0.2}, "sphere");
}

TEST(DecodeAccuracy, RgbcmyPanel) {
  const auto f = eval::renderSimFrame({"rig_2proj_1cam.json", "rgbcmy_panel"});
  expectWithin(measure(f, "rgbcmy panel"), {0.865, 0.97, 0, 0.0025, 0.2}, "rgbcmy panel");
}

TEST(DecodeAccuracy, CupsWithOcclusion) {
  const auto f = eval::renderSimFrame({"rig_2proj_1cam.json", "cups"});
  expectWithin(measure(f, "cups"), {0.94, 0.95, 0, 0.003, 0.2}, "cups");
}

TEST(DecodeAccuracy, Bunny) {
  const auto f = eval::renderSimFrame({"rig_2proj_1cam.json", "bunny"});
  expectWithin(measure(f, "bunny"), {0.94, 0.96, 0, 0.0038, 0.2}, "bunny");
}

TEST(DecodeAccuracy, StatueThreePatterns) {
  const auto f = eval::renderSimFrame({"rig_3proj_1cam.json", "statue"});
  expectWithin(measure(f, "statue 3 patterns"), {0.93, 0.96, 0.93, 0.003, 0.2}, "statue");
}

// Decoding boundary curves against decoding each scan line alone (DecodeParams::curves off: a
// pixel keeps its own windows' level, one window suffices). Curves give more depth on the scenes
// where decoding is hard (three patterns, a curved surface) at about as few gross errors: the
// fill between consecutive levels only drops the wrong levels either way (sphere: 0.17 % with
// curves, 0.16 % without).
TEST(DecodeAccuracy, CurvesBeatScanLines) {
  DecodeParams lines;
  lines.curves = false;
  lines.minCurveVotes = 1;
  for (const auto& [rigFile, scene] :
       {std::pair{"rig_3proj_1cam.json", "plane"}, std::pair{"rig_2proj_1cam.json", "sphere"}}) {
    const auto f = eval::renderSimFrame({rigFile, scene});
    const std::string label = std::string(scene) + (f.rig.projectors.size() == 3 ? " 3p" : "");
    const SceneFigures byLine = measure(f, label + " scan lines", 0, lines);
    const SceneFigures byCurve = measure(f, label + " curves", 0);
    EXPECT_GT(byCurve.mergedSmooth.completeness, byLine.mergedSmooth.completeness) << label;
    EXPECT_LE(byCurve.mergedAll.grossRate, byLine.mergedAll.grossRate + 0.0005) << label;
  }
}

// The gain the paper is about (§5, Table 2): more projectors light more of what the camera sees
// in one shot. The statue (a head scan) seen by one camera, decoded with the first 1, 2 and 3 of
// the three-projector rig's projectors (each rendered with only those projectors present):
// completeness = valid merged pixels / pixels where the camera sees the statue; relative
// amount = valid pixels / those of one projector. The paper's model for 1P1C, 2P1C, 3P1C has
// relative amounts 28 %, 54 %, 79 % of a full scan, i.e. 1 : 1.9 : 2.8.
TEST(DecodeAccuracy, MoreProjectorsSeeMoreOfTheObject) {
  const auto full = eval::loadExampleRig("rig_3proj_1cam.json");
  const auto scene = eval::loadNamedScene("statue");
  std::vector<double> completeness;
  std::vector<int> valid;
  for (std::size_t n = 1; n <= 3; ++n) {
    auto rig = full;
    rig.projectors.resize(n);
    const auto f = eval::renderSimFrame(rig, scene);
    const auto p = runCounted(f, 0);
    // The statue: pixels nearer than the wall behind it (the scene's background plane).
    eval::Mask object = eval::Mask::filled(f.depth.width, f.depth.height, 0);
    for (int y = 0; y < object.height; ++y) {
      for (int x = 0; x < object.width; ++x) {
        object.at(x, y) =
            std::isfinite(f.depth.at(x, y)) && f.depth.at(x, y) < kStatueBehindM ? 255 : 0;
      }
    }
    const eval::DepthScore s =
        eval::scoreDepth(p->pipeline->merged(), f.depth.view(), object.view());
    completeness.push_back(s.completeness);
    valid.push_back(s.valid - s.gross);
    std::printf(
        "statue, %zu projector(s): completeness %.4f of %d object pixels, relative amount "
        "%.2f, gross %.5f\n",
        n, s.completeness, s.regionPixels, static_cast<double>(valid.back()) / valid.front(),
        s.grossRate);
  }
  // Two projectors light 11 points more of the head than one (0.70 → 0.81).
  EXPECT_GT(completeness[1], completeness[0] + 0.05);
  // Three do not yet add to two: where all three patterns overlap on the curved, detailed head,
  // demultiplexing (second-order separation, 8 px direction tiles) finds broken boundaries and
  // fewer curves decode (0.66, with 2.8 % gross errors on the bust). A ratchet, not the target;
  // on the flat board three patterns decode as well as two (PlaneThreePatterns60Deg).
  EXPECT_GT(completeness[2], 0.62);
}

}  // namespace
}  // namespace smx::algo
