// Orientation demultiplexing against the simulator's ground truth (fixed seed, the paper's
// noise): encoding directions, boundary recall / precision / class and sub-pixel position, per
// projector, in the regions lit by exactly 1, 2 or 3 patterns (away from occlusion edges).
// Each case prints its figures (`demux_accuracy_test` alone prints the table quoted in notes).
//
// Targets (issue): directions median ≤ 2°, 95th percentile ≤ 5°; boundaries recall and precision
// ≥ 98 % (2 patterns) / ≥ 95 % (3), class ≥ 99 % (2 patterns) / ≥ 97 % (RGBCMY panel), position
// RMS ≤ 0.15 px. Where a target is not met yet the test asserts the measured level (a ratchet)
// and says so.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "demux_frame.hpp"
#include "smx/algo/demux.hpp"
#include "smx/eval/boundary_eval.hpp"
#include "smx/eval/sim_frame.hpp"

namespace smx::algo {
namespace {

struct Figures {
  eval::BoundaryScore boundaries;
  eval::AngleStats directions;
  eval::AngleStats directionsFound;  // where the pattern's lobe was found (nearest tile)
  double foundShare = 0;             // of the region
};

// The region's pixels whose nearest tile found projector p's lobe.
eval::Mask whereFound(const eval::Mask& region, const Demultiplexer& d, int p) {
  eval::Mask m = region;
  const int tilePx = d.layout().params.tilePx;
  const auto tilesX = static_cast<std::size_t>(d.layout().tilesX());
  for (int y = 0; y < m.height; ++y) {
    for (int x = 0; x < m.width; ++x) {
      const std::size_t t =
          static_cast<std::size_t>(y / tilePx) * tilesX + static_cast<std::size_t>(x / tilePx);
      if (d.tileDirections(p)[t].present == 0) {
        m.at(x, y) = 0;
      }
    }
  }
  return m;
}

// Projector p's figures where exactly `patterns` projectors light the surface, p among them,
// 3 px inside that region and away from depth jumps over 2 %.
Figures measure(const eval::SimFrame& f, const Demultiplexer& d, int p, int patterns,
                const std::string& label) {
  const eval::Mask region = test::regionLitBy(f, p, patterns);
  const eval::Mask found = whereFound(region, d, p);
  const auto stripe = f.stripe[static_cast<std::size_t>(p)].view();
  Figures fig{eval::scoreBoundaries(d.boundaries(p), d.directions(p), stripe, region.view()),
              eval::scoreDirections(d.directions(p), stripe, region.view()),
              eval::scoreDirections(d.directions(p), stripe, found.view()),
              static_cast<double>(found.count()) / std::max(region.count(), 1)};
  const auto& b = fig.boundaries;
  std::printf(
      "%-22s proj%d lit by %d: %6d px | direction median %.2f p95 %.2f deg (lobe found in "
      "%.1f %%: p95 %.2f) | boundaries %6d recall %.4f precision %.4f class %.4f position rms "
      "%.3f mean %+.3f px\n",
      label.c_str(), p, patterns, region.count(), fig.directions.medianDeg, fig.directions.p95Deg,
      100 * fig.foundShare, fig.directionsFound.p95Deg, b.trueBoundaries, b.recall, b.precision,
      b.classAccuracy, b.positionRmsPx, b.positionMeanPx);
  return fig;
}

struct Limits {
  double directionMedianDeg;
  double directionP95Deg;
  double recall;
  double precision;
  double classAccuracy;
  double positionRmsPx;
};

void expectWithin(const Figures& fig, const Limits& l, const std::string& what) {
  EXPECT_GT(fig.boundaries.trueBoundaries, 1000) << what;
  EXPECT_LE(fig.directions.medianDeg, l.directionMedianDeg) << what;
  EXPECT_LE(fig.directions.p95Deg, l.directionP95Deg) << what;
  EXPECT_GE(fig.boundaries.recall, l.recall) << what;
  EXPECT_GE(fig.boundaries.precision, l.precision) << what;
  EXPECT_GE(fig.boundaries.classAccuracy, l.classAccuracy) << what;
  EXPECT_LE(fig.boundaries.positionRmsPx, l.positionRmsPx) << what;
  EXPECT_EQ(fig.boundaries.wrongDirectionSign, 0) << what;
}

constexpr Limits kTwoPatternTargets{2.0, 5.0, 0.98, 0.98, 0.99, 0.15};

// The frames are rendered with 4 × 4 samples per pixel. With the scenes' 2 × 2, a stripe edge
// across a pixel covers 0, ½ or 1 of its samples, so the image itself places the edge only to
// within ½ px (an RMS of 0.14 px for axis-aligned stripes, whatever the estimator); a camera
// integrates over the whole pixel. RenderSamplingSetsThePositionFloor measures it.
constexpr int kSupersampling = 4;

eval::SimFrame render(const algo::Rig& rig, const std::string& scene,
                      int supersampling = kSupersampling) {
  return eval::renderSimFrame(rig, eval::loadNamedScene(scene), {.supersampling = supersampling});
}

eval::SimFrame render(const std::string& rigFile, const std::string& scene,
                      int supersampling = kSupersampling) {
  return render(eval::loadExampleRig(rigFile), scene, supersampling);
}

// Given the flat board rendered with 2 × 2, 4 × 4 and 6 × 6 samples per pixel, the position error
// falls with the sampling (the 2 × 2 render quantises the edges), while recall stays.
TEST(DemuxAccuracy, RenderSamplingSetsThePositionFloor) {
  double rms[3] = {};
  const int samplings[3] = {2, 4, 6};
  for (int i = 0; i < 3; ++i) {
    const auto f = render("rig_2proj_1cam.json", "plane", samplings[i]);
    const auto d = test::demultiplex(f);
    const Figures fig = measure(
        f, *d->demux, 0, 2,
        "plane " + std::to_string(samplings[i]) + "x" + std::to_string(samplings[i]) + " samples");
    EXPECT_GE(fig.boundaries.recall, 0.98);
    rms[i] = fig.boundaries.positionRmsPx;
  }
  EXPECT_GT(rms[0], 0.12) << "2 x 2 samples place an edge to within half a pixel";
  EXPECT_LT(rms[1], 0.7 * rms[0]);
  EXPECT_LT(rms[2], rms[1]);
}

// Given the flat board and two patterns 90° apart, every target holds for both projectors.
TEST(DemuxAccuracy, TwoPatterns90DegOnAPlaneMeetTheTargets) {
  const auto f = render("rig_2proj_1cam.json", "plane");
  const auto d = test::demultiplex(f);
  for (int p = 0; p < 2; ++p) {
    expectWithin(measure(f, *d->demux, p, 2, "plane 90deg"), kTwoPatternTargets,
                 "projector " + std::to_string(p));
  }
}

// The same with the second pattern turned to 70° from the first.
TEST(DemuxAccuracy, TwoPatterns70DegOnAPlaneMeetTheTargets) {
  auto rig = eval::loadExampleRig("rig_2proj_1cam.json");
  rig.projectors[1].pattern.angleDeg = 70.0;
  const auto f = render(rig, "plane");
  const auto d = test::demultiplex(f);
  for (int p = 0; p < 2; ++p) {
    expectWithin(measure(f, *d->demux, p, 2, "plane 70deg"), kTwoPatternTargets,
                 "projector " + std::to_string(p));
  }
}

// A sphere before a wall: curved surface, shadows, an occluding contour. Towards the sphere's rim
// one pattern arrives at grazing incidence and fades: its lobe is lost there (about 5 % of the
// region) and the direction is guessed from the tiles around, so the 95th percentile is far off
// target (ratchet: 10°) while it meets it where the lobe was found; recall, precision, class and
// position meet the targets (class only since tiles take their own surface's lobe at the contour
// and found directions grow into the rim: 98.8 % before).
TEST(DemuxAccuracy, TwoPatternsOnASphere) {
  const auto f = render("rig_2proj_1cam.json", "sphere");
  const auto d = test::demultiplex(f);
  for (int p = 0; p < 2; ++p) {
    const Figures both = measure(f, *d->demux, p, 2, "sphere 90deg");
    expectWithin(both, {1.0, 10.0, 0.98, 0.98, 0.99, 0.15}, "projector " + std::to_string(p));
    EXPECT_LE(both.directionsFound.p95Deg, 5.0) << "projector " << p;
    EXPECT_GE(both.foundShare, 0.9) << "projector " << p;
    expectWithin(measure(f, *d->demux, p, 1, "sphere 90deg"), {1.0, 1.0, 0.985, 0.99, 0.99, 0.15},
                 "projector " + std::to_string(p) + " alone");
  }
}

// Three patterns 60° apart on the board: every target holds for each projector.
TEST(DemuxAccuracy, ThreePatterns60DegOnAPlane) {
  const auto f = render("rig_3proj_1cam.json", "plane");
  const auto d = test::demultiplex(f);
  for (int p = 0; p < 3; ++p) {
    expectWithin(measure(f, *d->demux, p, 3, "plane 3 x 60deg"), {2.0, 5.0, 0.98, 0.99, 0.99, 0.15},
                 "projector " + std::to_string(p));
  }
}

// The RGBCMY panel (paper Fig. 13): strong surface colours, divided out by the local average.
// Every target holds (97 % class on the panel). The position is where the colour edges bite:
// 0.17 px when it came from the relative strengths (each sample with its own tile's divisor,
// a dark channel's noise scaled up).
TEST(DemuxAccuracy, TwoPatternsOnTheRgbcmyPanel) {
  const auto f = render("rig_2proj_1cam.json", "rgbcmy_panel");
  const auto d = test::demultiplex(f);
  for (int p = 0; p < 2; ++p) {
    expectWithin(measure(f, *d->demux, p, 2, "rgbcmy panel 90deg"),
                 {2.0, 5.0, 0.98, 0.98, 0.97, 0.15}, "projector " + std::to_string(p));
  }
}

}  // namespace
}  // namespace smx::algo
