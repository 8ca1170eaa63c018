// The realism suite (smx/eval/realism_case.hpp, realism_eval.hpp): the generated rigs checked
// against the product's envelope with geometry computed here and on renders of the truth, the
// regions on inputs whose answer is known by construction, and a fixed-seed subset of the suite
// as a regression guard.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <vector>

#include "smx/algo/lens.hpp"
#include "smx/eval/realism_attribution.hpp"
#include "smx/eval/realism_case.hpp"
#include "smx/eval/realism_eval.hpp"
#include "smx/eval/suite.hpp"
#include "smx/eval/wrong_depth.hpp"

namespace smx::eval {
namespace {

constexpr std::uint64_t kSeed = 1;
constexpr double kDeg = std::numbers::pi / 180.0;

double distanceM(const algo::DeviceModel& a, const algo::DeviceModel& b) {
  const auto ca = algo::lens::centre(a);
  const auto cb = algo::lens::centre(b);
  return std::hypot(ca[0] - cb[0], ca[1] - cb[1], ca[2] - cb[2]);
}

bool anyNonZero(const std::array<double, 5>& d) {
  return std::ranges::any_of(d, [](double v) { return v != 0.0; });
}

// Given the same seed and index, when a case is generated twice, then rig and scene are the
// same; another index gives another rig.
TEST(RealismGenerator, SameSeedAndIndexGiveTheSameCase) {
  const auto a = generateRealismCase(kSeed, 3);
  const auto b = generateRealismCase(kSeed, 3);
  const auto c = generateRealismCase(kSeed, 4);
  ASSERT_EQ(a.rig.projectors.size(), b.rig.projectors.size());
  for (std::size_t p = 0; p < a.rig.projectors.size(); ++p) {
    EXPECT_EQ(a.rig.projectors[p].K, b.rig.projectors[p].K);
    EXPECT_EQ(a.rig.projectors[p].R, b.rig.projectors[p].R);
    EXPECT_EQ(a.rig.projectors[p].t, b.rig.projectors[p].t);
    EXPECT_EQ(a.rig.projectors[p].pattern.stripePx, b.rig.projectors[p].pattern.stripePx);
  }
  ASSERT_EQ(a.scene.objects.size(), b.scene.objects.size());
  for (std::size_t i = 0; i < a.scene.objects.size(); ++i) {
    EXPECT_EQ(a.scene.objects[i].pose.t, b.scene.objects[i].pose.t);
  }
  EXPECT_EQ(a.summary, b.summary);
  EXPECT_NE(a.rig.projectors[0].t, c.rig.projectors[0].t);
}

// Given 40 cases, then each has 2–3 projectors and 1–2 cameras (every count occurs), every
// camera–projector baseline (device centres, computed here) is 8–25 cm, the working distance is
// 0.5–1.2 m with every device aimed at the target on cam0's axis (the target projects into
// every image, at the projectors' image centre), cameras are 640 × 480 with lens distortion,
// projectors 1024 × 768 or 1280 × 800 with their principal point 10–40 % of the height below the
// centre (lens shift) and distortion exactly when asked for.
TEST(RealismGenerator, RigsHonourTheEnvelope) {
  std::set<std::size_t> projectorCounts;
  std::set<std::size_t> cameraCounts;
  for (int i = 0; i < 40; ++i) {
    const bool distorted = i % 2 == 0;
    const auto c = generateRealismCase(kSeed, i, {.projectorDistortion = distorted});
    SCOPED_TRACE("case " + std::to_string(i) + ": " + c.summary);
    const auto& rig = c.rig;
    projectorCounts.insert(rig.projectors.size());
    cameraCounts.insert(rig.cameras.size());
    ASSERT_GE(rig.projectors.size(), 2U);
    ASSERT_LE(rig.projectors.size(), 3U);
    ASSERT_GE(rig.cameras.size(), 1U);
    ASSERT_LE(rig.cameras.size(), 2U);
    EXPECT_GE(c.workingDistanceM, 0.5);
    EXPECT_LE(c.workingDistanceM, 1.2);
    const algo::lens::Point3 target{0, 0, c.workingDistanceM};
    for (const auto& cam : rig.cameras) {
      EXPECT_EQ(cam.width, 640);
      EXPECT_EQ(cam.height, 480);
      EXPECT_TRUE(anyNonZero(cam.dist));
      const auto at = algo::lens::project(cam, target);
      ASSERT_TRUE(at);
      EXPECT_NEAR(at->x, cam.cx(), 0.05 * cam.width);
      EXPECT_NEAR(at->y, cam.cy(), 0.05 * cam.height);
      for (const auto& proj : rig.projectors) {
        const double b = distanceM(cam, proj);
        EXPECT_GE(b, 0.08);
        EXPECT_LE(b, 0.25);
      }
    }
    for (const auto& proj : rig.projectors) {
      EXPECT_TRUE((proj.width == 1024 && proj.height == 768) ||
                  (proj.width == 1280 && proj.height == 800));
      const double shift = (proj.cy() - (proj.height - 1) / 2.0) / proj.height;
      EXPECT_GE(shift, 0.10);
      EXPECT_LE(shift, 0.40);
      EXPECT_EQ(anyNonZero(proj.dist), distorted);
      const auto at = algo::lens::project(proj, target);
      ASSERT_TRUE(at);
      EXPECT_NEAR(at->x, (proj.width - 1) / 2.0, 0.03 * proj.width);
      EXPECT_NEAR(at->y, (proj.height - 1) / 2.0, 2.0);
    }
  }
  EXPECT_EQ(projectorCounts, (std::set<std::size_t>{2, 3}));
  EXPECT_EQ(cameraCounts, (std::set<std::size_t>{1, 2}));
}

// Mean unit stripe gradient (angle, radians) and median width 1/|∇s| of projector p in a
// window around cam0's principal point, from the truth.
struct Measured {
  double angleRad = 0;
  double widthPx = 0;
};
Measured measureNearCentre(const SimFrame& f, int p, int halfWindow) {
  const auto& cam = f.rig.cameras[0];
  const auto stripe = f.stripe[static_cast<std::size_t>(p)].view();
  double sx = 0;
  double sy = 0;
  std::vector<double> widths;
  const int x0 = static_cast<int>(std::lround(cam.cx()));
  const int y0 = static_cast<int>(std::lround(cam.cy()));
  for (int y = y0 - halfWindow; y <= y0 + halfWindow; ++y) {
    for (int x = x0 - halfWindow; x <= x0 + halfWindow; ++x) {
      if (const auto g = stripeGradient(stripe, x, y)) {
        sx += g->ux();
        sy += g->uy();
        widths.push_back(1.0 / g->magnitude);
      }
    }
  }
  if (widths.empty()) {
    return {std::numeric_limits<double>::quiet_NaN(), 0};
  }
  std::ranges::sort(widths);
  return {std::atan2(sy, sx), widths[widths.size() / 2]};
}

// The angle between two lines, degrees in [0, 90].
double lineAngleDeg(double a, double b) {
  double d = std::fmod(std::abs(a - b) / kDeg, 180.0);
  return d > 90 ? 180 - d : d;
}

// Given cases whose scene is replaced by a wide fronto-parallel wall at the working distance,
// when cam0 renders it, then near the image centre the truth stripes of every projector are
// 3–8 px wide (and as designed, within 3 %), and the encoding axes of every two projectors are
// 60–90° apart (within 1.5° for perspective across the window).
TEST(RealismGenerator, StripeWidthAndAxesMeasuredOnTheTruthAtTheWorkingDistance) {
  for (int i = 0; i < 8; ++i) {
    auto c = generateRealismCase(kSeed, i, {.projectorDistortion = true});
    SCOPED_TRACE("case " + std::to_string(i) + ": " + c.summary);
    sim::Scene wall = c.scene;
    wall.objects.clear();
    sim::Object plane;
    plane.shape = sim::Plane{4.0, 4.0};
    plane.pose.t = sim::Vec3(0, 0, c.workingDistanceM);
    wall.objects.push_back(plane);
    wall.supersampling = 1;
    const SimFrame f = renderSimFrame(c.rig, wall, {.camera = 0});
    std::vector<double> angles;
    for (int p = 0; p < static_cast<int>(c.rig.projectors.size()); ++p) {
      const auto m = measureNearCentre(f, p, 10);
      ASSERT_TRUE(std::isfinite(m.angleRad)) << "projector " << p << " does not light the centre";
      EXPECT_GE(m.widthPx, 3.0 * 0.99) << "projector " << p;
      EXPECT_LE(m.widthPx, 8.0 * 1.01) << "projector " << p;
      EXPECT_NEAR(m.widthPx, c.stripeWidthPx[static_cast<std::size_t>(p)], 0.03 * m.widthPx)
          << "projector " << p;
      angles.push_back(m.angleRad);
    }
    for (std::size_t a = 0; a < angles.size(); ++a) {
      for (std::size_t b = a + 1; b < angles.size(); ++b) {
        const double between = lineAngleDeg(angles[a], angles[b]);
        EXPECT_GE(between, 60.0 - 1.5) << "projectors " << a << ", " << b;
        EXPECT_LE(between, 90.0 + 1.5) << "projectors " << a << ", " << b;
      }
    }
  }
}

// Given a depth image with a step from 1.0 m to 1.2 m between columns 9 and 10 and no surface
// (NaN) from column 30 on, then the band holds exactly the pixels within 2 px of those edges.
TEST(RealismRegions, DiscontinuityBandIsTwoPixelsAroundDepthStepsAndSilhouettes) {
  constexpr int kW = 40;
  constexpr int kH = 8;
  OwnedPlane<float> depth(kW, kH, 1.0F);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      depth.pixels[static_cast<std::size_t>((y * kW) + x)] =
          x >= 30 ? std::numeric_limits<float>::quiet_NaN() : (x >= 10 ? 1.2F : 1.0F);
    }
  }
  const Mask band = discontinuityBand(depth.view(), 2);
  for (int x = 0; x < kW; ++x) {
    const bool expected = (x >= 7 && x <= 12) || (x >= 27 && x <= 32);
    EXPECT_EQ(band.at(x, 4) != 0, expected) << "column " << x;
  }
}

// A frame lit by one projector whose stripes are w px wide along x (s = x / w + 10) on a flat
// surface at 1 m.
SimFrame stripedFrame(double widthPx) {
  constexpr int kW = 48;
  constexpr int kH = 32;
  SimFrame f;
  f.depth = OwnedPlane<float>(kW, kH, 1.0F);
  f.lit.emplace_back(kW, kH, std::uint8_t{255});
  f.stripe.emplace_back(kW, kH, 0.0F);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      f.stripe[0].pixels[static_cast<std::size_t>((y * kW) + x)] =
          static_cast<float>((x / widthPx) + 10.0);
    }
  }
  return f;
}

// Given stripes 3 px wide the smooth interior is resolvable and their median width is 3 px;
// stripes 2 px wide are not resolvable anywhere.
TEST(RealismRegions, ResolvableWhereTheTrueStripesAreAtLeast2Point5PxWide) {
  const SimFrame wide = stripedFrame(3.0);
  const Mask smooth = litRegion(wide, {.smooth = true});
  EXPECT_GT(smooth.count(), 0);
  EXPECT_EQ(resolvableRegion(wide).count(), smooth.count());
  EXPECT_NEAR(medianStripeWidthPx(wide, 0), 3.0, 1e-3);
  EXPECT_EQ(resolvableRegion(stripedFrame(2.0)).count(), 0);
}

// Given two scores, then their sum weighs each by its pixels: completeness and gross rate are
// ratios of summed counts, RMSE the root of the inlier-weighted mean square.
TEST(RealismRegions, AggregatesArePixelWeighted) {
  DepthScore a;
  a.regionPixels = 100;
  a.valid = 90;
  a.gross = 0;
  a.inliers = 90;
  a.rmseMm = 1.0;
  DepthScore b;
  b.regionPixels = 900;
  b.valid = 450;
  b.gross = 45;
  b.inliers = 405;
  b.rmseMm = 2.0;
  const std::array scores{a, b};
  const DepthScore s = sumScores(scores);
  EXPECT_NEAR(s.completeness, 540.0 / 1000.0, 1e-12);
  EXPECT_NEAR(s.grossRate, 45.0 / 540.0, 1e-12);
  EXPECT_NEAR(s.rmseMm, std::sqrt(((90 * 1.0) + (405 * 4.0)) / 495.0), 1e-12);
}

// Given a case whose projector 0 has a degenerate pattern (stripes 0 px wide), when it runs, then
// every camera's run is reported as refused with the pipeline's reason instead of throwing, and
// the worst-run ranking leaves it out.
TEST(RealismRuns, ARigThePipelineRefusesIsReportedWithItsReason) {
  auto c = generateRealismCase(kSeed, 0, {.projectorDistortion = false, .cameraScale = 0.25});
  c.rig.projectors[0].pattern.stripePx = 0;
  const auto runs = runRealismCase(c, kSeed, 1);
  ASSERT_EQ(runs.size(), c.rig.cameras.size());
  for (const auto& r : runs) {
    EXPECT_TRUE(r.refused);
    EXPECT_FALSE(r.reason.empty());
    EXPECT_EQ(r.lit.regionPixels, 0);
  }
  EXPECT_TRUE(worstRuns(runs, 5).empty());
}

// A hand-built scored frame, 168 × 12, in seven zones of 24 columns, each built to meet one cause
// first: A lit by projector 0 alone with stripes 2.8 px wide (narrow, and single too); B lit by
// projector 0 alone, 5 px (single); C lit by both, 5 px, a flat grey image (dim); D lit by both,
// 5 px, a column checker, a plane 80° from the camera axis (grazing); E as D on a fronto-parallel
// plane (other); F as E with a depth step 3 columns right of its scored pixels (edge); G as E
// lit by a third projector too (triple). Each zone's scored pixels (columns 9–14, rows 4–7:
// 24), more than 8 px from every depth step but F's, carry a known number of gross depths and
// then of missing ones.
constexpr int kZoneW = 24;
constexpr int kZones = 7;
constexpr int kAttrW = kZoneW * kZones;
constexpr int kAttrH = 12;
// Zones A–G; E (other) comes before F and G, unlike the causes.
constexpr std::array kGrossPerZone{3, 2, 1, 4, 5, 6, 7};
constexpr std::array kMissingPerZone{2, 3, 4, 6, 1, 5, 3};
constexpr std::array kZoneCause{Cause::kNarrow, Cause::kSingle, Cause::kDim,   Cause::kGrazing,
                                Cause::kOther,  Cause::kEdge,   Cause::kTriple};
constexpr double kFx = 1000.0;
constexpr double kCx = 72.0;

bool scored(int x, int y) {
  const int u = x % kZoneW;
  return u >= 9 && u <= 14 && y >= 4 && y <= 7;
}

algo::DeviceModel device(double centreX) {
  algo::DeviceModel d;
  d.width = kAttrW;
  d.height = kAttrH;
  d.K = {kFx, 0, kCx, 0, kFx, 6.0, 0, 0, 1};
  d.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  d.t = {-centreX, 0, 0};
  return d;
}

struct AttributionFixture {
  SimFrame frame;
  OwnedPlane<std::uint16_t> merged;
  Mask region;
};

AttributionFixture attributionFixture() {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  AttributionFixture a;
  SimFrame& f = a.frame;
  f.rig.cameras.push_back({device(0.0)});
  f.rig.projectors.push_back({device(-0.1), {}});
  f.rig.projectors.push_back({device(0.1), {}});
  f.rig.projectors.push_back({device(0.2), {}});
  f.image = OwnedPlane<algo::Rgb8>(kAttrW, kAttrH, algo::Rgb8{100, 100, 100});
  f.depth = OwnedPlane<float>(kAttrW, kAttrH, 1.0F);
  f.lit.assign(3, OwnedPlane<std::uint8_t>(kAttrW, kAttrH, 0));
  f.stripe.assign(3, OwnedPlane<float>(kAttrW, kAttrH, kNaN));
  a.merged = OwnedPlane<std::uint16_t>(kAttrW, kAttrH, 0);
  a.region = Mask::filled(kAttrW, kAttrH, 0);
  const double tan80 = std::tan(80.0 * kDeg);
  for (int y = 0; y < kAttrH; ++y) {
    for (int x = 0; x < kAttrW; ++x) {
      const auto i = static_cast<std::size_t>((y * kAttrW) + x);
      const int zone = x / kZoneW;
      f.lit[0].pixels[i] = 255;
      f.stripe[0].pixels[i] = static_cast<float>(
          x < kZoneW ? 10.0 + (x / 2.8) : 10.0 + (kZoneW / 2.8) + ((x - kZoneW) / 5.0));
      if (zone >= 2) {
        f.lit[1].pixels[i] = 255;
        f.stripe[1].pixels[i] = static_cast<float>(10.0 + (x / 5.0));
      }
      if (zone == 6) {
        f.lit[2].pixels[i] = 255;
        f.stripe[2].pixels[i] = static_cast<float>(10.0 + (x / 5.0));
      }
      if (zone != 2) {
        const std::uint8_t v = x % 2 == 0 ? 200 : 0;
        f.image.pixels[i] = {v, v, v};
      }
      // z − tan 80°·X = 1 with X = z·(x − cx) / fx: a plane whose normal is 80° off the axis.
      double z = zone == 3 ? 1.0 / (1.0 - (tan80 * (x - kCx) / kFx)) : 1.0;
      z = zone == 5 && x % kZoneW >= 17 ? 1.2 : z;
      f.depth.pixels[i] = static_cast<float>(z);
      a.merged.pixels[i] = static_cast<std::uint16_t>(std::lround(z / algo::kDefaultDepthUnitM));
    }
  }
  std::array<int, kZones> seen{};
  for (int y = 0; y < kAttrH; ++y) {
    for (int x = 0; x < kAttrW; ++x) {
      if (!scored(x, y)) {
        continue;
      }
      const auto zone = static_cast<std::size_t>(x / kZoneW);
      const auto i = static_cast<std::size_t>((y * kAttrW) + x);
      a.region.at(x, y) = 255;
      const int k = seen[zone]++;
      if (k < kGrossPerZone[zone]) {
        a.merged.pixels[i] =
            static_cast<std::uint16_t>(a.merged.pixels[i] + std::lround(0.05 / 1e-4));
      } else if (k < kGrossPerZone[zone] + kMissingPerZone[zone]) {
        a.merged.pixels[i] = 0;
      }
    }
  }
  return a;
}

// Given the five-zone frame, then every zone's pixels meet exactly the conditions it was built
// with, and the counts per first cause are the zone's gross and missing pixels.
TEST(RealismAttribution, CountsPerCauseMatchTheConstructedFrame) {
  const auto fx = attributionFixture();
  const auto bit = [](Cause c) { return 1U << static_cast<unsigned>(c); };
  const std::array<unsigned, kZones> conditions{bit(Cause::kNarrow) | bit(Cause::kSingle),
                                                bit(Cause::kSingle),
                                                bit(Cause::kDim),
                                                bit(Cause::kGrazing),
                                                0U,
                                                bit(Cause::kEdge),
                                                bit(Cause::kTriple)};
  const Mask nearEdge = discontinuityBand(fx.frame.depth.view(), kNearEdgePx);
  for (int zone = 0; zone < kZones; ++zone) {
    for (int x = zone * kZoneW; x < (zone + 1) * kZoneW; ++x) {
      if (scored(x, 5)) {
        EXPECT_EQ(pixelConditions(fx.frame, 0, nearEdge, x, 5),
                  conditions[static_cast<std::size_t>(zone)])
            << "zone " << zone << ", column " << x;
      }
    }
  }
  const Attribution a = attributeRun(fx.frame, 0, fx.merged.view(), fx.region, fx.region);
  for (std::size_t zone = 0; zone < kZones; ++zone) {
    const auto c = static_cast<std::size_t>(kZoneCause[zone]);
    SCOPED_TRACE(causeName(kZoneCause[zone]));
    EXPECT_EQ(a.outsideBand[c].region, 24);
    EXPECT_EQ(a.outsideBand[c].gross, kGrossPerZone[zone]);
    EXPECT_EQ(a.outsideBand[c].valid, 24 - kMissingPerZone[zone]);
    EXPECT_EQ(a.resolvable[c].missing(), kMissingPerZone[zone]);
  }
  // Single also holds in zone A, where narrow comes first.
  EXPECT_EQ(a.outsideBandWith[static_cast<std::size_t>(Cause::kSingle)].region, 48);
  EXPECT_EQ(a.outsideBandWith[static_cast<std::size_t>(Cause::kSingle)].gross, 5);
  EXPECT_NEAR(grossShare(a, Cause::kGrazing), 4.0 / 28.0, 1e-12);
  EXPECT_NEAR(missingShare(a, Cause::kDim), 4.0 / 24.0, 1e-12);
  // 168 pixels, 144 with depth, 28 gross; zones A and B (single) hold 43 valid, 5 gross.
  EXPECT_NEAR(grossRateWithout(a, std::nullopt), 28.0 / 144.0, 1e-12);
  EXPECT_NEAR(grossRateWithout(a, Cause::kSingle), 23.0 / 101.0, 1e-12);
  EXPECT_NEAR(completenessWithout(a, Cause::kNarrow), 122.0 / 144.0, 1e-12);
  EXPECT_NEAR(grossRateWithout(a, Cause::kOther), 5.0 / 23.0, 1e-12);
}

// Given runs, then their attribution sums count by count.
TEST(RealismAttribution, SumsAddTheCounts) {
  const auto fx = attributionFixture();
  const Attribution a = attributeRun(fx.frame, 0, fx.merged.view(), fx.region, fx.region);
  const std::array runs{a, a};
  const Attribution s = sumAttributions(runs);
  EXPECT_EQ(s.outsideBand[1].gross, 2 * kGrossPerZone[1]);
  EXPECT_EQ(s.resolvableWith[0].region, 2 * 24);
  EXPECT_NEAR(grossRateWithout(s, Cause::kSingle), 23.0 / 101.0, 1e-12);
}

// Six pixels in a row, the truth 1 m deep with projector 0's stripe coordinate 50 + x and
// projector 1's 80 + x (unlit at x = 4): each gross pixel of the region goes to one kind, by the
// first projector with depth there.
TEST(WrongDepthKinds, EachGrossPixelIsCountedOnceByItsKind) {
  constexpr int kW = 6;
  constexpr double kUnitM = 1e-4;
  const auto q16 = [](double s) { return static_cast<algo::StripeQ16>(std::lround(s * 65536)); };
  std::vector<OwnedPlane<float>> truthStripes{OwnedPlane<float>(kW, 1, 0.0F),
                                              OwnedPlane<float>(kW, 1, 0.0F)};
  const OwnedPlane<float> truthDepth(kW, 1, 1.0F);
  std::vector<std::vector<algo::StripeQ16>> s(2, std::vector<algo::StripeQ16>(kW, algo::kNoStripe));
  std::vector<std::vector<std::uint16_t>> z(2, std::vector<std::uint16_t>(kW, algo::kNoDepth));
  std::vector<std::uint16_t> merged(kW, algo::kNoDepth);
  for (int x = 0; x < kW; ++x) {
    truthStripes[0].pixels[static_cast<std::size_t>(x)] = 50.0F + static_cast<float>(x);
    truthStripes[1].pixels[static_cast<std::size_t>(x)] = 80.0F + static_cast<float>(x);
  }
  truthStripes[1].pixels[4] = std::numeric_limits<float>::quiet_NaN();
  const auto put = [&](int p, int x, double stripeError, std::uint16_t depth) {
    const auto i = static_cast<std::size_t>(x);
    s[static_cast<std::size_t>(p)][i] =
        q16(truthStripes[static_cast<std::size_t>(p)].pixels[i] + stripeError);
    z[static_cast<std::size_t>(p)][i] = depth;
  };
  put(0, 0, 0.0, 10000);  // right: not counted
  merged[0] = 10000;
  put(0, 1, 3.0, 9000);  // 10 cm off, three stripes: level, alone
  merged[1] = 9000;
  put(0, 2, 0.3, 10300);  // 3 cm off, a third of a stripe, with projector 1: position, corroborated
  put(1, 2, 0.3, 10300);
  merged[2] = 10300;
  z[1][4] = 8000;  // projector 1 alone where it does not light: unlit
  merged[4] = 8000;
  put(0, 5, 0.6, 11000);  // level, alone, but outside the region
  merged[5] = 11000;
  Mask region = Mask::filled(kW, 1, 255);
  region.at(5, 0) = 0;
  std::vector<algo::ConstStripePlane> stripes;
  std::vector<algo::ConstDepthPlane> depths;
  for (std::size_t p = 0; p < 2; ++p) {
    stripes.push_back(*algo::ConstStripePlane::packed(s[p], kW, 1));
    depths.push_back(*algo::ConstDepthPlane::packed(z[p], kW, 1));
  }
  const WrongDepth w = classifyWrongDepth(stripes, depths, truthStripes,
                                          *algo::ConstDepthPlane::packed(merged, kW, 1),
                                          truthDepth.view(), region, kUnitM);
  const auto at = [&w](int corroborated, WrongKind k) {
    return w.gross[static_cast<std::size_t>(corroborated)][static_cast<std::size_t>(k)];
  };
  EXPECT_EQ(at(0, WrongKind::kLevel), 1);
  EXPECT_EQ(at(1, WrongKind::kPosition), 1);
  EXPECT_EQ(at(0, WrongKind::kUnlit), 1);
  EXPECT_EQ(w.total(), 3);
  const std::vector<WrongDepth> twice{w, w};
  EXPECT_EQ(sumWrongDepth(twice).total(), 6);
  EXPECT_EQ(sumWrongDepth(twice).gross[1][static_cast<std::size_t>(WrongKind::kPosition)], 2);
  EXPECT_STREQ(wrongKindName(WrongKind::kLevel), "level");
  EXPECT_STREQ(wrongKindName(WrongKind::kUnlit), "unlit");
}

// The fixed-seed CI subset: the first 12 cases as `stripemux eval --only realism` renders them
// (640 × 480 cameras, projector lens distortion, the simulator's real optics; smaller cameras
// would shrink the stripes below what the product's envelope promises). The limits are
// regression guards, not the targets (gross outside the band ≤ 0.1 %, resolvable
// completeness ≥ 95 %, quoted in docs/results.md): measured 0.12 % and 90.0 % with the trust
// filter's working range, with a margin of 0.08 and 2 points. Raise them as the pipeline improves.
TEST(RealismSuite, FixedSeedSubsetStaysWithinItsGuards) {
  SuiteOptions o;
  o.seed = kSeed;
  o.sections = {Section::kRealism};
  o.realismCases = 12;
  o.realism = {.projectorDistortion = true, .cameraScale = 1.0};
  const Report r = runSuite(o);
  std::vector<DepthScore> band;
  std::vector<DepthScore> resolvable;
  for (const auto& run : r.realism.runs) {
    EXPECT_FALSE(run.refused) << "case " << run.caseIndex << ": " << run.reason;
    band.push_back(run.outsideBand);
    resolvable.push_back(run.resolvable);
  }
  const DepthScore b = sumScores(band);
  const DepthScore c = sumScores(resolvable);
  std::cout << "realism subset: " << r.realism.runs.size() << " runs, gross outside band "
            << 100.0 * b.grossRate << " %, resolvable completeness " << 100.0 * c.completeness
            << " %\n";
  EXPECT_LE(b.grossRate, 0.002);
  EXPECT_GE(c.completeness, 0.88);
}

}  // namespace
}  // namespace smx::eval
