// Triangulation of the simulator's exact stripe coordinate reproduces its exact depth: what is
// left is the fixed-point tables' rounding and the depth unit (docs/triangulation.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "smx/algo/triangulation.hpp"
#include "smx/eval/sim_frame.hpp"

namespace smx::algo {
namespace {

struct Errors {
  int compared = 0;
  int missing = 0;  // truth stripe and depth finite, but no depth out
  double rmsUnits = 0;
  double maxUnits = 0;
};

Errors triangulateTruth(const eval::SimFrame& f, int camera, int projector) {
  const auto tables = buildTriangulationTables(f.rig, camera, projector, kDefaultDepthUnitM);
  EXPECT_TRUE(tables) << (tables ? "" : tables.error());
  const int w = f.image.width;
  const int h = f.image.height;
  std::vector<std::byte> memory(*Triangulator::workspaceBytes(w, h));
  Arena arena(memory);
  const auto t = Triangulator::create(*tables, arena);
  EXPECT_TRUE(t);
  std::vector<StripeQ16> stripe(static_cast<std::size_t>(w * h), kNoStripe);
  const auto& truth = f.stripe[static_cast<std::size_t>(projector)];
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float s = truth.at(x, y);
      if (std::isfinite(s) && s >= 0 && s < 198) {
        stripe[static_cast<std::size_t>(y * w + x)] =
            static_cast<StripeQ16>(std::lround(s * kStripeOne));
      }
    }
  }
  std::vector<std::uint16_t> depth(static_cast<std::size_t>(w * h));
  EXPECT_TRUE(t->run(*ConstStripePlane::packed(stripe, w, h), *DepthPlane::packed(depth, w, h)));
  Errors e;
  double sum2 = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const auto i = static_cast<std::size_t>(y * w + x);
      const float z = f.depth.at(x, y);
      if (stripe[i] == kNoStripe || !std::isfinite(z)) {
        continue;
      }
      if (depth[i] == kNoDepth) {
        ++e.missing;
        continue;
      }
      ++e.compared;
      const double err = depth[i] - z / kDefaultDepthUnitM;
      sum2 += err * err;
      e.maxUnits = std::max(e.maxUnits, std::abs(err));
    }
  }
  e.rmsUnits = e.compared > 0 ? std::sqrt(sum2 / e.compared) : 0;
  return e;
}

// Given renders with exact truth, when the truth's stripe coordinate (rounded to Q16) is
// triangulated, then the depth is the truth's to within the rounding of z to 0.1 mm units and
// of s to 2^-16 stripe (≈ 0.02 unit here), for both cameras of the two-camera rig (the second
// one rotated and displaced) and every projector.
TEST(TriangulationSim, TruthStripeGivesTruthDepth) {
  for (const char* scene : {"plane", "sphere"}) {
    for (int camera = 0; camera < 2; ++camera) {
      const auto f = eval::renderSimFrame(
          {.rigFile = "rig_2proj_2cam.json", .scene = scene, .camera = camera});
      for (int p = 0; p < 2; ++p) {
        const Errors e = triangulateTruth(f, camera, p);
        std::printf("%-7s cam%d proj%d: %d px, rms %.3f max %.3f units, %d missing\n", scene,
                    camera, p, e.compared, e.rmsUnits, e.maxUnits, e.missing);
        EXPECT_GT(e.compared, 50000) << scene << " cam" << camera << " proj" << p;
        EXPECT_EQ(e.missing, 0) << scene << " cam" << camera << " proj" << p;
        EXPECT_LT(e.rmsUnits, 0.35) << scene << " cam" << camera << " proj" << p;
        EXPECT_LT(e.maxUnits, 0.7) << scene << " cam" << camera << " proj" << p;
      }
    }
  }
}

}  // namespace
}  // namespace smx::algo
