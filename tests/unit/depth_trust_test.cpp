// The per-pair trust filter (depth_trust.hpp) and the merge's vote, against the simulator's truth:
// the decoded stripes' position error that fixes δ, stripes along the epipolar direction, stripes
// narrower than the detector separates, and a steeply tilted plane on which one projector's
// stripes are about 2 px wide in the camera.
#include "smx/algo/depth_trust.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "smx/algo/camera_pipeline.hpp"
#include "smx/eval/boundary_eval.hpp"
#include "smx/eval/frame_eval.hpp"
#include "smx/eval/sim_frame.hpp"

namespace smx::algo {
namespace {

// The truth stripe plane of projector p as the decoder's Q16 coordinate.
std::vector<StripeQ16> truthStripe(const eval::SimFrame& f, int p) {
  const auto& s = f.stripe.at(static_cast<std::size_t>(p));
  std::vector<StripeQ16> q(s.pixels.size(), kNoStripe);
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (std::isfinite(s.pixels[i])) {
      q[i] = static_cast<StripeQ16>(std::lround(s.pixels[i] * kStripeOne));
    }
  }
  return q;
}

// The median truth stripe width (1 / |∇s|) of projector p in the camera, pixels.
double medianWidthPx(const eval::SimFrame& f, int p) {
  std::vector<double> w;
  const auto s = f.stripe.at(static_cast<std::size_t>(p)).view();
  for (int y = 0; y < f.image.height; y += 2) {
    for (int x = 0; x < f.image.width; x += 2) {
      if (const auto g = eval::stripeGradient(s, x, y); g && g->magnitude > 0) {
        w.push_back(1 / g->magnitude);
      }
    }
  }
  if (w.empty()) {
    return 0;
  }
  std::nth_element(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(w.size() / 2), w.end());
  return w[w.size() / 2];
}

// Triangulates the truth stripe coordinate of projector p, `levelError` stripes off in the
// pixels `wrong` marks, and runs the trust filter on it: per pixel 1 where a depth was kept, 0
// where it was dropped, −1 where there was none.
std::vector<int> trusted(const eval::SimFrame& f, int p, const DepthTrustParams& params,
                         int levelError = 0, const std::vector<bool>& wrong = {}) {
  auto tables = buildTriangulationTables(f.rig, 0, p, kDefaultDepthUnitM);
  EXPECT_TRUE(tables) << tables.error();
  const int w = f.image.width;
  const int h = f.image.height;
  std::vector<std::byte> memory(*Triangulator::workspaceBytes(w, h));
  Arena arena(memory);
  auto t = Triangulator::create(*tables, arena);
  EXPECT_TRUE(t);
  auto s = truthStripe(f, p);
  for (std::size_t i = 0; i < wrong.size(); ++i) {
    if (wrong[i] && s[i] != kNoStripe) {
      s[i] = std::clamp(s[i] + levelError * kStripeOne, 0, Triangulator::kMaxStripe - 1);
    }
  }
  std::vector<std::uint16_t> z(s.size());
  std::vector<std::uint8_t> c(s.size());
  const auto stripe = *ConstStripePlane::packed(s, w, h);
  EXPECT_TRUE(t->run(stripe, *DepthPlane::packed(z, w, h)));
  std::vector<int> kept(z.size(), -1);
  for (std::size_t i = 0; i < z.size(); ++i) {
    kept[i] = z[i] != kNoDepth ? 0 : -1;
  }
  const test::AllocationCounter counter;
  EXPECT_TRUE(trustDepth(*t, stripe, *DepthPlane::packed(z, w, h),
                         *ImageView<std::uint8_t>::packed(c, w, h), params));
  EXPECT_EQ(counter.allocations(), 0U);
  for (std::size_t i = 0; i < z.size(); ++i) {
    EXPECT_EQ(z[i] != kNoDepth, c[i] != 0) << "confidence 0 exactly where there is no depth";
    kept[i] = z[i] != kNoDepth ? 1 : kept[i];
  }
  return kept;
}

double keptShare(const std::vector<int>& kept) {
  const auto had = std::count_if(kept.begin(), kept.end(), [](int k) { return k >= 0; });
  const auto stay = std::count(kept.begin(), kept.end(), 1);
  EXPECT_GT(had, 10000);
  return static_cast<double>(stay) / static_cast<double>(had);
}

// δ = 0.2 px and the margin 2δ come from this: the decoded stripe coordinate's error along the
// stripe gradient, in camera pixels, on the named scenes (smooth lit pixels, errors under 1 px:
// wrong levels are the gross errors' business). The RMS (σ) must stay within δ and 3σ within 2δ.
TEST(DepthTrust, DecodedPositionErrorIsWithinTheAssumedDelta) {
  const DepthTrustParams params;
  const double delta = params.boundaryErrorQ8 / 256.0;
  for (const auto& [rigFile, scene] :
       {std::pair{"rig_2proj_1cam.json", "plane"}, std::pair{"rig_2proj_1cam.json", "sphere"},
        std::pair{"rig_3proj_1cam.json", "statue"}}) {
    const auto f = eval::renderSimFrame({rigFile, scene});
    const auto run = eval::runPipeline(f, 0);
    for (int p = 0; p < run->pipeline->projectors(); ++p) {
      const auto region = eval::litRegion(f, {.smooth = true, .projector = p});
      const auto truth = f.stripe.at(static_cast<std::size_t>(p)).view();
      const auto decoded = run->pipeline->stripe(p);
      double sum = 0;
      int n = 0;
      for (int y = 0; y < f.image.height; ++y) {
        for (int x = 0; x < f.image.width; ++x) {
          const StripeQ16 s = decoded.rowPtr(y)[x];
          const auto g = eval::stripeGradient(truth, x, y);
          if (region.pixels[static_cast<std::size_t>(y * f.image.width + x)] == 0 || s < 0 || !g ||
              g->magnitude <= 0) {
            continue;
          }
          const double e = (s / double{kStripeOne} - truth.rowPtr(y)[x]) / g->magnitude;
          if (std::abs(e) < 1.0) {
            sum += e * e;
            ++n;
          }
        }
      }
      ASSERT_GT(n, 10000) << scene;
      const double sigma = std::sqrt(sum / n);
      std::printf("%s %s proj%d: decoded position error %.3f px RMS over %d px\n", rigFile, scene,
                  p, sigma, n);
      EXPECT_LE(sigma, delta) << scene << " proj" << p;
      EXPECT_LE(3 * sigma, params.errorMargin * delta) << scene << " proj" << p;
    }
  }
}

// Stripes along the epipolar direction: the stripe coordinate hardly changes along the
// camera–projector baseline, dz/ds is huge, and a boundary error of a fraction of a pixel is a
// gross depth error. proj0 of rig_2proj_1cam sits beside the camera (horizontal baseline; its
// epipole lies far to the left, so the epipolar lines fan out by a few degrees over the image):
// on the truth stripe coordinate, its pattern at 0° (stripes across the baseline) is kept
// everywhere, and the share kept falls as the stripes turn towards the baseline.
TEST(DepthTrust, StripesAlongTheEpipolarDirectionGiveNoDepth) {
  double previous = 1.0;
  for (const double angle : {0.0, 80.0, 85.0, 90.0}) {
    auto rig = eval::loadExampleRig("rig_2proj_1cam.json");
    rig.projectors[0].pattern.angleDeg = angle;
    rig.projectors[1].pattern.angleDeg = angle == 0.0 ? 90.0 : 0.0;
    const auto f = eval::renderSimFrame(rig, eval::loadNamedScene("plane"));
    const double kept = keptShare(trusted(f, 0, {}));
    std::printf("pattern at %.0f deg: %.4f kept\n", angle, kept);
    if (angle == 0.0) {
      EXPECT_GE(kept, 0.99);
    } else {
      EXPECT_LT(kept, previous) << angle;
    }
    previous = kept;
  }
  EXPECT_LE(previous, 0.2);
}

// Stripes narrower than 2.5 px give no depth, wider ones do, pixel by pixel against the truth
// stripe width 1 / |∇s| (±5 %: |∇s| is estimated within 4 %): the plane's stripes scaled to a
// median of 2.2 px and 2.8 px; only resolvability judged (a tolerance nothing exceeds).
TEST(DepthTrust, StripesNarrowerThanTheDetectorSeparatesGiveNoDepth) {
  auto rig = eval::loadExampleRig("rig_2proj_1cam.json");
  const auto reference = eval::renderSimFrame(rig, eval::loadNamedScene("plane"));
  const double width = medianWidthPx(reference, 0);
  DepthTrustParams resolvability;
  resolvability.tolerance = {65535, 0};
  const double limit = resolvability.minStripeWidthQ8 / 256.0;
  for (const double target : {2.2, 2.8}) {
    auto narrow = rig;
    narrow.projectors[0].pattern.stripePx *= target / width;
    const auto f = eval::renderSimFrame(narrow, eval::loadNamedScene("plane"));
    const auto kept = trusted(f, 0, resolvability);
    const auto truth = f.stripe.at(0).view();
    int narrowKept = 0;
    int narrowAll = 0;
    int wideDropped = 0;
    int wideAll = 0;
    for (int y = 0; y < f.image.height; ++y) {
      for (int x = 0; x < f.image.width; ++x) {
        const int k = kept[static_cast<std::size_t>(y * f.image.width + x)];
        const auto g = eval::stripeGradient(truth, x, y);
        if (k < 0 || !g || g->magnitude <= 0) {
          continue;
        }
        const double w = 1.0 / g->magnitude;
        if (w < 0.95 * limit) {
          ++narrowAll;
          narrowKept += k;
        } else if (w > 1.05 * limit) {
          ++wideAll;
          wideDropped += 1 - k;
        }
      }
    }
    std::printf("stripes %.2f px: %d of %d narrower than the limit kept, %d of %d wider dropped\n",
                medianWidthPx(f, 0), narrowKept, narrowAll, wideDropped, wideAll);
    EXPECT_GT(narrowAll + wideAll, 100000);
    EXPECT_LE(narrowKept, narrowAll / 100);
    EXPECT_LE(wideDropped, wideAll / 100);
  }
}

// A plane turned 45° about the vertical towards proj0, whose stripes are made narrower so that
// they are about 2 px wide in the camera (the case: ~2.3 px, 77 % of that pair wrong):
// proj0 gives almost no depth, and the merged image has at most 0.1 % gross errors while proj1
// (4 px) still covers the plane.
TEST(DepthTrust, ATiltedPlaneWithTwoPixelStripesGivesNoWrongDepth) {
  auto rig = eval::loadExampleRig("rig_2proj_1cam.json");
  rig.projectors[0].pattern.stripePx *= 0.6;
  auto scene = eval::loadNamedScene("plane");
  scene.objects.at(0).pose.R =
      Eigen::AngleAxisd(-std::numbers::pi / 4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const auto f = eval::renderSimFrame(rig, scene);
  const double width0 = medianWidthPx(f, 0);
  const double width1 = medianWidthPx(f, 1);
  ASSERT_GT(width0, 1.8);
  ASSERT_LT(width0, 2.3);
  ASSERT_GT(width1, 3.5);
  const auto run = eval::runPipeline(f, 0);
  const auto fig = eval::measureFrame(f, 0, *run->pipeline);
  std::printf(
      "stripes %.2f / %.2f px: proj0 %.4f complete (gross %.4f), proj1 %.4f; merged %.4f "
      "complete, gross %.5f (%d px)\n",
      width0, width1, fig.pairs[0].completeness, fig.pairs[0].grossRate, fig.pairs[1].completeness,
      fig.mergedAll.completeness, fig.mergedAll.grossRate, fig.mergedAll.gross);
  EXPECT_LE(fig.pairs[0].completeness, 0.10);
  EXPECT_GE(fig.pairs[1].completeness, 0.95);
  EXPECT_LE(fig.mergedAll.grossRate, 0.001);
  EXPECT_GE(fig.mergedAll.completeness, 0.85);
}

// The merged confidence against the truth on the sphere and the bunny: 0 exactly where there is
// no depth, and the depths with a high confidence are nearer the truth than those with a low one.
TEST(DepthTrust, MergedConfidenceFollowsTheTrueError) {
  const int kSplit = 230;  // most merged depths lie between 200 and 240 on these scenes
  for (const char* scene : {"sphere", "bunny"}) {
    const auto f = eval::renderSimFrame({"rig_2proj_1cam.json", scene});
    const auto run = eval::runPipeline(f, 0);
    const auto z = run->pipeline->merged();
    const auto c = run->pipeline->confidence();
    const double unitMm = kDefaultDepthUnitM * 1000;
    std::array<double, 2> sum{};
    std::array<int, 2> count{};
    for (int y = 0; y < f.image.height; ++y) {
      for (int x = 0; x < f.image.width; ++x) {
        const std::uint16_t depth = z.rowPtr(y)[x];
        const std::uint8_t confidence = c.rowPtr(y)[x];
        ASSERT_EQ(depth == kNoDepth, confidence == 0) << scene << " at " << x << "," << y;
        const float truth = f.depth.at(x, y);
        if (depth == kNoDepth || !std::isfinite(truth)) {
          continue;
        }
        const double errorMm = depth * unitMm - truth * 1000.0;
        if (std::abs(errorMm) > 5.0) {
          continue;  // gross: the RMSE's business is the rest
        }
        const auto bin = static_cast<std::size_t>(confidence >= kSplit ? 1 : 0);
        sum[bin] += errorMm * errorMm;
        ++count[bin];
      }
    }
    ASSERT_GT(count[0], 1000) << scene;
    ASSERT_GT(count[1], 1000) << scene;
    const double low = std::sqrt(sum[0] / count[0]);
    const double high = std::sqrt(sum[1] / count[1]);
    std::printf("%s: RMSE %.3f mm below confidence %d (%d px), %.3f mm from it (%d px)\n", scene,
                low, kSplit, count[0], high, count[1]);
    EXPECT_LT(high, low) << scene;
  }
}

// Every 6-transition window of the pattern is valid (docs/pattern.md), so a misread one decodes
// to a level far from the true one; on the realism suite most such depths land below half the
// true depth. On this rig, with its wide baseline, the plane lies about 100 stripes of disparity
// from proj0: a patch decoded 60 stripes off towards the far side leaves the working range
// (0.45–1.8 m) and is dropped, while without the range (the trust filter's defaults) it stays;
// 30 stripes off either way stays inside the range and is kept: the range is no check of the
// level itself, only of where the depth lands.
TEST(DepthTrust, AStripeLevelFarOffFallsOutsideTheWorkingRange) {
  const auto rig = eval::loadExampleRig("rig_2proj_1cam.json");
  const auto f = eval::renderSimFrame(rig, eval::loadNamedScene("plane"));
  PipelineOptions options;
  options.nominalDepthM = 0.9;
  const auto setup = prepareCameraPipeline(rig, 0, options);
  ASSERT_TRUE(setup) << setup.error();
  EXPECT_EQ(setup->trust.nearUnits, 4500);
  EXPECT_EQ(setup->trust.farUnits, 18000);
  const int w = f.image.width;
  std::vector<bool> patch(f.stripe.at(0).pixels.size());
  for (std::size_t i = 0; i < patch.size(); ++i) {
    const int x = static_cast<int>(i) % w;
    const int y = static_cast<int>(i) / w;
    patch[i] = std::abs(x - w / 2) < 60 && std::abs(y - f.image.height / 2) < 60;
  }
  const auto share = [&](const std::vector<int>& kept) {
    int inPatch = 0;
    int stay = 0;
    int outsideDropped = 0;
    for (std::size_t i = 0; i < kept.size(); ++i) {
      if (patch[i] && kept[i] >= 0) {
        ++inPatch;
        stay += kept[i];
      } else if (!patch[i] && kept[i] == 0) {
        ++outsideDropped;
      }
    }
    EXPECT_GT(inPatch, 10000);
    return std::pair{static_cast<double>(stay) / inPatch, outsideDropped};
  };
  for (const int levelError : {60, 30, -30}) {
    SCOPED_TRACE(levelError);
    const auto [ranged, rangedLost] = share(trusted(f, 0, setup->trust, levelError, patch));
    const auto [unranged, unrangedLost] = share(trusted(f, 0, {}, levelError, patch));
    std::printf("%+d stripes: %.4f of the patch kept in the working range, %.4f without\n",
                levelError, ranged, unranged);
    EXPECT_GE(unranged, 0.9);
    if (levelError == 60) {
      EXPECT_LE(ranged, 0.01);
    } else {
      EXPECT_EQ(ranged, unranged);
    }
    EXPECT_EQ(rangedLost, unrangedLost) << "the plane itself lies inside the range";
  }
}

TEST(DepthTrust, RejectsParametersNamingTheField) {
  const auto message = [](DepthTrustParams p) {
    auto r = validateDepthTrust(p);
    return r ? std::string() : std::string(r.error().message);
  };
  DepthTrustParams p;
  EXPECT_EQ(message(p), "");
  p.boundaryErrorQ8 = 257;
  EXPECT_NE(message(p).find("boundaryErrorQ8"), std::string::npos);
  p = {};
  p.minStripeWidthQ8 = -1;
  EXPECT_NE(message(p).find("minStripeWidthQ8"), std::string::npos);
  p = {};
  p.errorMargin = 0;
  EXPECT_NE(message(p).find("errorMargin"), std::string::npos);
  p = {};
  p.tolerance.minUnits = 0;
  EXPECT_NE(message(p).find("tolerance.minUnits"), std::string::npos);
  p = {};
  p.tolerance.permille = 1001;
  EXPECT_NE(message(p).find("tolerance.permille"), std::string::npos);
  p = {};
  p.nearUnits = 0;
  EXPECT_NE(message(p).find("working range"), std::string::npos);
  p = {};
  p.nearUnits = 2000;
  p.farUnits = 1999;
  EXPECT_NE(message(p).find("working range"), std::string::npos);
}

}  // namespace
}  // namespace smx::algo
