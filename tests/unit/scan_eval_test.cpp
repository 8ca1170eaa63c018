// The turntable evaluation's accounting (docs/scan-results.md): every part of the seen surface
// the mesh misses is put down to exactly one cause, and the cleaning margin it reports changes
// what is fused.
#include <gtest/gtest.h>

#include "smx/scan_eval/turntable_eval.hpp"

namespace smx::scan_eval {
namespace {

TEST(ScanEval, EveryMissHasOneCauseAndANarrowerMarginCoversMore) {
  TurntableEvalOptions options;
  options.views = 6;
  options.voxelM = 0.002;
  options.supersampling = 1;
  const TurntableEvalResult r = runTurntableEval(options);

  EXPECT_EQ(r.fusedViews, 6);
  EXPECT_GT(r.coverage, 0.3);
  EXPECT_LT(r.meanMm, 1.0);
  EXPECT_NEAR(r.coverage + r.missedUndecoded + r.missedCleaned + r.missedUnmeshed, 1.0, 1e-9);
  EXPECT_GT(r.missedUndecoded, 0.0);  // six views leave parts of the bunny undecoded
  EXPECT_GT(r.missedCleaned, 0.0);
  // Six views see much of the bunny only at grazing incidence; what some view sees nearly
  // head-on is covered better than the whole.
  EXPECT_GT(r.wellSeenShare, 0.3);
  EXPECT_LT(r.wellSeenShare, 1.0);
  EXPECT_GT(r.wellSeenCoverage, r.coverage);

  ASSERT_EQ(r.margins.size(), 3U);
  EXPECT_EQ(r.margins[0].edgePx, 2);
  EXPECT_DOUBLE_EQ(r.margins[0].coverage, r.coverage);
  EXPECT_EQ(r.margins[1].edgePx, 1);
  EXPECT_EQ(r.margins[2].edgePx, 0);
  EXPECT_GT(r.margins[1].coverage, r.margins[0].coverage);
  EXPECT_GT(r.margins[2].coverage, r.margins[1].coverage);
}

}  // namespace
}  // namespace smx::scan_eval
