// Triangulation against double-precision geometry built from the lens model alone: points at
// known depths along camera pixel rays, their stripe coordinate from projecting them into the
// projector (lens::project + stripeCoordinate), then the integer triangulation of that
// coordinate must give the depth back.
#include "smx/algo/triangulation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include "alloc_counter.hpp"
#include "smx/algo/depth_trust.hpp"
#include "smx/algo/lens.hpp"
#include "smx/algo/pattern_image.hpp"

namespace smx::algo {
namespace {

// Rotation about y by a degrees, then a device centre c: t = −R·c.
void place(DeviceModel& d, double yawDeg, double pitchDeg, lens::Point3 centre) {
  const double a = yawDeg * std::numbers::pi / 180.0;
  const double b = pitchDeg * std::numbers::pi / 180.0;
  const std::array<double, 9> ry = {std::cos(a), 0, -std::sin(a), 0, 1, 0,
                                    std::sin(a), 0, std::cos(a)};
  const std::array<double, 9> rx = {1,          0, 0, 0, std::cos(b), std::sin(b), 0, -std::sin(b),
                                    std::cos(b)};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      double v = 0;
      for (int k = 0; k < 3; ++k) {
        v += rx[static_cast<std::size_t>(r * 3 + k)] * ry[static_cast<std::size_t>(k * 3 + c)];
      }
      d.R[static_cast<std::size_t>(r * 3 + c)] = v;
    }
  }
  for (int i = 0; i < 3; ++i) {
    const auto row = static_cast<std::size_t>(3 * i);
    d.t[static_cast<std::size_t>(i)] =
        -(d.R[row] * centre[0] + d.R[row + 1] * centre[1] + d.R[row + 2] * centre[2]);
  }
}

// A distorted camera at the origin looking down +z, and a projector 0.25 m to its right and
// 0.1 m up, turned towards the middle of the working volume, its pattern at 30°.
Rig makeRig() {
  Rig rig;
  Camera cam;
  cam.id = "cam0";
  cam.width = 320;
  cam.height = 240;
  cam.K = {400, 0, 159.5, 0, 402, 119.25, 0, 0, 1};
  cam.dist = {-0.12, 0.05, 0.0007, -0.0004, 0.0};
  place(cam, 0, 0, {0, 0, 0});
  Projector proj;
  proj.id = "proj0";
  proj.width = 800;
  proj.height = 600;
  proj.K = {1100, 0, 399.5, 0, 1100, 299.5, 0, 0, 1};
  proj.pattern = {30.0, 5.0, 0.0};
  place(proj, -14, 6, {0.25, -0.1, 0.0});
  rig.cameras.push_back(cam);
  rig.projectors.push_back(proj);
  return rig;
}

struct Sample {
  int x;
  int y;
  double zM;
  std::optional<double> stripe;  // where the projector sees the point
};

// The world point at camera depth z on pixel (x, y)'s ray, and its stripe coordinate.
Sample sampleAt(const Rig& rig, int x, int y, double zM) {
  const Camera& cam = rig.cameras[0];
  const Projector& proj = rig.projectors[0];
  const auto ray = lens::pixelRay(cam, {static_cast<double>(x), static_cast<double>(y)});
  const lens::Point3 ahead{ray->origin[0] + ray->direction[0], ray->origin[1] + ray->direction[1],
                           ray->origin[2] + ray->direction[2]};
  const double zPerMetre = lens::toDevice(cam, ahead)[2];  // camera z per unit along the ray
  const double along = zM / zPerMetre;
  const lens::Point3 world{ray->origin[0] + along * ray->direction[0],
                           ray->origin[1] + along * ray->direction[1],
                           ray->origin[2] + along * ray->direction[2]};
  Sample s{x, y, zM, std::nullopt};
  if (const auto uv = lens::project(proj, world)) {
    s.stripe = stripeCoordinate(proj.pattern, proj.width, proj.height, uv->x, uv->y);
  }
  return s;
}

StripeQ16 q16(double s) {
  return static_cast<StripeQ16>(std::lround(s * kStripeOne));
}

class Triangulation : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto tables = buildTriangulationTables(rig_, 0, 0, kDefaultDepthUnitM);
    ASSERT_TRUE(tables) << tables.error();
    memory_.resize(*Triangulator::workspaceBytes(rig_.cameras[0].width, rig_.cameras[0].height));
    arena_.emplace(memory_);
    auto t = Triangulator::create(*tables, *arena_);
    ASSERT_TRUE(t);
    tri_.emplace(*t);
  }

  Rig rig_ = makeRig();
  std::vector<std::byte> memory_;
  std::optional<Arena> arena_;
  std::optional<Triangulator> tri_;
};

// Given random pixels and depths 0.4–2.5 m, the depth comes back to within half a depth unit
// (rounding) plus what s's Q16 rounding moves it (≤ 2^-17 stripe: < 0.05 unit here).
TEST_F(Triangulation, RecoversTheDepthOfPointsSeenByBoth) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> px(0, 319);
  std::uniform_int_distribution<int> py(0, 239);
  std::uniform_real_distribution<double> depth(0.4, 2.5);
  int checked = 0;
  double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const Sample s = sampleAt(rig_, px(rng), py(rng), depth(rng));
    if (!s.stripe || *s.stripe < 0 || *s.stripe >= 198) {
      continue;
    }
    const std::uint16_t z = tri_->depthAt(s.x, s.y, q16(*s.stripe));
    const double error = std::abs(z - s.zM / kDefaultDepthUnitM);
    worst = std::max(worst, error);
    ASSERT_LE(error, 0.55) << s.x << "," << s.y << " z " << s.zM;
    ++checked;
  }
  EXPECT_GT(checked, 10000);
  EXPECT_GT(worst, 0.3);  // the comparison is at the unit's resolution, not looser
}

TEST_F(Triangulation, NoDepthWithoutAStripeBehindTheCameraOrOutOfRange) {
  const Sample near = sampleAt(rig_, 100, 80, 1.0);
  ASSERT_TRUE(near.stripe);
  EXPECT_NE(tri_->depthAt(100, 80, q16(*near.stripe)), kNoDepth);
  EXPECT_EQ(tri_->depthAt(100, 80, kNoStripe), kNoDepth);
  EXPECT_EQ(tri_->depthAt(100, 80, -1), kNoDepth);
  EXPECT_EQ(tri_->depthAt(100, 80, Triangulator::kMaxStripe), kNoDepth);
  // Beyond 6.5535 m the depth does not fit 16 bits at 0.1 mm.
  const Sample far = sampleAt(rig_, 160, 120, 7.0);
  ASSERT_TRUE(far.stripe);
  EXPECT_EQ(tri_->depthAt(160, 120, q16(*far.stripe)), kNoDepth);
}

// Along one pixel's ray the stripe coordinate seen by the projector sweeps an interval as the
// depth goes from 5 cm to 6.55 m. Every s inside it triangulates to the depth where the ray
// meets it; every s outside it (its plane meets the ray behind the camera, behind the projector
// or beyond the 16-bit range) gives no depth.
TEST_F(Triangulation, ExactlyTheStripesTheRaySweepsHaveADepth) {
  int outside = 0;
  for (const auto& [x, y] : {std::pair{10, 10}, std::pair{160, 120}, std::pair{300, 230}}) {
    double sMin = 1e9;
    double sMax = -1e9;
    for (int i = 0; i <= 4000; ++i) {
      const Sample s = sampleAt(rig_, x, y, 0.05 + i * (6.5 / 4000));
      ASSERT_TRUE(s.stripe);
      sMin = std::min(sMin, *s.stripe);
      sMax = std::max(sMax, *s.stripe);
    }
    int inside = 0;
    for (double target = 0.05; target < 198; target += 0.37) {
      const std::uint16_t z = tri_->depthAt(x, y, q16(target));
      if (target > sMin + 0.01 && target < sMax - 0.01) {
        ASSERT_NE(z, kNoDepth) << target;
        // Within the depth unit's rounding: target lies between the stripes at z ± 0.6 unit.
        const Sample lo = sampleAt(rig_, x, y, (z - 0.6) * kDefaultDepthUnitM);
        const Sample hi = sampleAt(rig_, x, y, (z + 0.6) * kDefaultDepthUnitM);
        EXPECT_LE(std::min(*lo.stripe, *hi.stripe), target + 2e-5) << target;
        EXPECT_GE(std::max(*lo.stripe, *hi.stripe), target - 2e-5) << target;
        ++inside;
      } else if (target < sMin - 0.01 || target > sMax + 0.01) {
        EXPECT_EQ(z, kNoDepth) << x << "," << y << " s " << target << " in [" << sMin << ", "
                               << sMax << "]";
        ++outside;
      }
    }
    EXPECT_GT(inside, 10);
  }
  EXPECT_GT(outside, 10);
}

TEST_F(Triangulation, RunFillsThePlaneWithoutTouchingTheHeap) {
  const int w = rig_.cameras[0].width;
  const int h = rig_.cameras[0].height;
  std::vector<StripeQ16> stripe(static_cast<std::size_t>(w * h), kNoStripe);
  std::vector<double> truth(stripe.size(), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Sample s = sampleAt(rig_, x, y, 0.8 + 0.001 * x);
      if (s.stripe && *s.stripe >= 0 && *s.stripe < 198) {
        stripe[static_cast<std::size_t>(y * w + x)] = q16(*s.stripe);
        truth[static_cast<std::size_t>(y * w + x)] = s.zM / kDefaultDepthUnitM;
      }
    }
  }
  std::vector<std::uint16_t> depth(stripe.size(), 1234);
  const test::AllocationCounter counter;
  ASSERT_TRUE(tri_->run(*ConstStripePlane::packed(stripe, w, h), *DepthPlane::packed(depth, w, h)));
  EXPECT_EQ(counter.allocations(), 0U);
  int filled = 0;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    if (stripe[i] == kNoStripe) {
      EXPECT_EQ(depth[i], kNoDepth);
    } else {
      EXPECT_NEAR(depth[i], truth[i], 0.55);
      ++filled;
    }
  }
  EXPECT_GT(filled, w * h / 2);

  std::vector<std::uint16_t> small(static_cast<std::size_t>((w - 1) * h));
  const auto r =
      tri_->run(*ConstStripePlane::packed(stripe, w, h), *DepthPlane::packed(small, w - 1, h));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, Errc::kSizeMismatch);
}

// A projector mounted 0.4 m ahead of the camera, on its axis: a camera ray meets a stripe plane
// behind the projector for some s (a point the projector cannot light). Every depth returned must
// be in front of both devices and reproject to its stripe.
TEST(TriangulationTables, IntersectionsBehindTheProjectorHaveNoDepth) {
  Rig rig = makeRig();
  place(rig.projectors[0], 0, 0, {0.05, 0.0, 0.4});
  const auto tables = buildTriangulationTables(rig, 0, 0, kDefaultDepthUnitM);
  ASSERT_TRUE(tables);
  std::vector<std::byte> memory(*Triangulator::workspaceBytes(320, 240));
  Arena arena(memory);
  const auto t = Triangulator::create(*tables, arena);
  ASSERT_TRUE(t);
  int returned = 0;
  for (int y = 0; y < 240; y += 20) {
    for (int x = 0; x < 320; x += 20) {
      for (double target = 0.25; target < 198; target += 0.5) {
        const std::uint16_t z = t->depthAt(x, y, q16(target));
        if (z == kNoDepth) {
          continue;
        }
        ++returned;
        const Sample lo = sampleAt(rig, x, y, (z - 0.6) * kDefaultDepthUnitM);
        const Sample hi = sampleAt(rig, x, y, (z + 0.6) * kDefaultDepthUnitM);
        ASSERT_TRUE(lo.stripe && hi.stripe)
            << x << "," << y << " s " << target << ": z " << z << " is behind the projector";
        // (+ 2^-16 stripe: s itself was rounded to Q16)
        ASSERT_LE(std::min(*lo.stripe, *hi.stripe), target + 2e-5) << x << "," << y << " z " << z;
        ASSERT_GE(std::max(*lo.stripe, *hi.stripe), target - 2e-5) << x << "," << y << " z " << z;
      }
    }
  }
  EXPECT_GT(returned, 1000);
}

// Where a point lands in the projector image: its stripe is lit only inside it.
bool insideProjector(const Rig& rig, int x, int y, double zM) {
  const Camera& cam = rig.cameras[0];
  const Projector& proj = rig.projectors[0];
  const auto local = lens::devicePoint(cam, {static_cast<double>(x), static_cast<double>(y)}, zM);
  const auto uv = lens::project(proj, lens::toWorld(cam, *local));
  return uv && uv->x >= -0.5 && uv->y >= -0.5 && uv->x <= proj.width - 0.5 &&
         uv->y <= proj.height - 0.5;
}

Result<Triangulator> triangulatorFor(const TriangulationTables& tables,
                                     std::vector<std::byte>& memory) {
  memory.resize(*Triangulator::workspaceBytes(tables));
  Arena arena(memory);
  return Triangulator::create(tables, arena);
}

constexpr double kNominalM = 0.9;

// The triangulator of the rig's one pair, fitted at kNominalM, in `memory`.
std::optional<Triangulator> pairTriangulator(const Rig& rig, std::vector<std::byte>& memory) {
  const auto tables = buildTriangulationTables(rig, 0, 0, kDefaultDepthUnitM, kNominalM);
  EXPECT_TRUE(tables) << (tables ? "" : tables.error());
  if (!tables) {
    return std::nullopt;
  }
  auto t = triangulatorFor(*tables, memory);
  EXPECT_TRUE(t);
  return t ? std::optional<Triangulator>(*t) : std::nullopt;
}

// Given a projector with a realistic lens (barrel, a little tangential), when exact stripe
// coordinates of points on pixel rays (lens::project, the simulator's own model) are
// triangulated, then every depth within the working range (0.45–1.8 m) is within 0.1 mm of the
// true one, and every point inside the projector image gets a depth.
TEST(DistortedProjector, ExactStripeGivesTheDepthWithinATenthOfAMillimetre) {
  Rig rig = makeRig();
  rig.projectors[0].dist = {-0.05, 0.01, 0.001, -0.0005, 0.0};
  const auto tables = buildTriangulationTables(rig, 0, 0, kDefaultDepthUnitM, kNominalM);
  ASSERT_TRUE(tables) << tables.error();
  EXPECT_FALSE(tables->numerators.empty());
  std::vector<std::byte> memory;
  const auto t = triangulatorFor(*tables, memory);
  ASSERT_TRUE(t);
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> px(0, 319);
  std::uniform_int_distribution<int> py(0, 239);
  std::uniform_real_distribution<double> inverseDepth(1.0 / 1.8, 1.0 / 0.45);
  int checked = 0;
  double worst = 0;
  for (int i = 0; i < 40000; ++i) {
    const Sample s = sampleAt(rig, px(rng), py(rng), 1.0 / inverseDepth(rng));
    if (!s.stripe || *s.stripe < 0 || *s.stripe >= 198 || !insideProjector(rig, s.x, s.y, s.zM)) {
      continue;
    }
    const std::uint16_t z = t->depthAt(s.x, s.y, q16(*s.stripe));
    ASSERT_NE(z, kNoDepth) << s.x << "," << s.y << " z " << s.zM;
    const double errorM = std::abs(z * kDefaultDepthUnitM - s.zM);
    worst = std::max(worst, errorM);
    ASSERT_LE(errorM, 0.0001) << s.x << "," << s.y << " z " << s.zM;
    ++checked;
  }
  EXPECT_GT(checked, 15000);
  std::printf(
      "distorted projector: %d points, worst %.4f mm (fit: %.4f mm at %.2f m, %.4f mm "
      "over the range)\n",
      checked, worst * 1000, tables->nominalResidualM * 1000, kNominalM,
      tables->rangeResidualM * 1000);
}

// The same tables through run(): the per-pixel numerators, still without the heap.
TEST(DistortedProjector, RunMatchesDepthAtWithoutTouchingTheHeap) {
  Rig rig = makeRig();
  rig.projectors[0].dist = {0.04, 0.0, 0.0, 0.0, 0.0};
  std::vector<std::byte> memory;
  const auto t = pairTriangulator(rig, memory);
  ASSERT_TRUE(t);
  const int w = rig.cameras[0].width;
  const int h = rig.cameras[0].height;
  std::vector<StripeQ16> stripe(static_cast<std::size_t>(w * h), kNoStripe);
  std::vector<double> truth(stripe.size(), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Sample s = sampleAt(rig, x, y, 0.7 + 0.002 * x);
      if (s.stripe && *s.stripe >= 0 && *s.stripe < 198 && insideProjector(rig, x, y, s.zM)) {
        stripe[static_cast<std::size_t>(y * w + x)] = q16(*s.stripe);
        truth[static_cast<std::size_t>(y * w + x)] = s.zM / kDefaultDepthUnitM;
      }
    }
  }
  std::vector<std::uint16_t> depth(stripe.size(), 1234);
  const test::AllocationCounter counter;
  ASSERT_TRUE(t->run(*ConstStripePlane::packed(stripe, w, h), *DepthPlane::packed(depth, w, h)));
  EXPECT_EQ(counter.allocations(), 0U);
  int filled = 0;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    if (stripe[i] == kNoStripe) {
      EXPECT_EQ(depth[i], kNoDepth);
    } else {
      EXPECT_NEAR(depth[i], truth[i], 1.0) << i;
      ++filled;
    }
  }
  EXPECT_GT(filled, w * h / 3);
}

constexpr int kOneOverPxQ24 = 1 << 24;  // 1 stripe per px in Q16, times the width's Q8

// The one-pass schedule of triangulation and trust (triangulateTrusted) against run() followed
// by trustDepth(), bit for bit: a surface's stripe plane with noise, holes of every negative
// value, jumps, values near and past the end of the sequence, ramps at the resolvable limit, for
// an undistorted and a distorted projector, with parameters at and between their limits; the
// schedule never touches the heap.
TEST(TriangulationWithTrust, OnePassGivesTheReferenceOnRandomStripes) {
  for (const bool distorted : {false, true}) {
    Rig rig = makeRig();
    rig.projectors[0].pattern.stripePx = 14;  // about 5 px in the camera: resolvable
    if (distorted) {
      rig.projectors[0].dist = {-0.05, 0.01, 0.001, -0.0005, 0.0};
    }
    std::vector<std::byte> memory;
    const auto t = pairTriangulator(rig, memory);
    ASSERT_TRUE(t);
    const int w = rig.cameras[0].width;
    const int h = rig.cameras[0].height;
    std::mt19937 rng(distorted ? 5 : 3);
    std::uniform_int_distribution<int> percent(0, 99);
    std::uniform_int_distribution<int> noise(-300, 300);
    std::vector<StripeQ16> stripe(static_cast<std::size_t>(w * h), kNoStripe);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const auto i = static_cast<std::size_t>(y * w + x);
        const Sample s = sampleAt(rig, x, y, 0.6 + 0.002 * x + 0.0005 * y);
        const int roll = percent(rng);
        if (y >= 10 && y < 40) {
          // Ramps at the default's resolvable limit (2^24 / 640 Q16 per px) and either side of
          // it, in bands of three equal rows.
          stripe[i] =
              x * (kOneOverPxQ24 / DepthTrustParams{}.minStripeWidthQ8 - 1 + (y - 10) / 3 % 3);
        } else if (roll < 3 || !s.stripe) {
          const std::array<StripeQ16, 3> holes{kNoStripe, -1, -70000};
          stripe[i] = holes[static_cast<std::size_t>(roll % 3)];
        } else if (roll < 4) {
          stripe[i] = Triangulator::kMaxStripe - 1 - roll;  // the end of the sequence
        } else if (roll < 5) {
          stripe[i] = Triangulator::kMaxStripe + roll;
        } else if (roll < 6) {
          stripe[i] = static_cast<StripeQ16>(percent(rng) * kStripeOne * 2);  // a jump
        } else if (roll < 7 && y > 200) {
          stripe[i] = std::numeric_limits<StripeQ16>::max() - percent(rng);  // hostile
        } else {
          stripe[i] = std::max(0, q16(*s.stripe) + noise(rng));
        }
      }
    }
    const auto stripePlane = *ConstStripePlane::packed(stripe, w, h);
    DepthTrustParams defaults;
    std::vector<DepthTrustParams> variants(6, defaults);
    variants[1].minStripeWidthQ8 = 0;
    variants[2].minStripeWidthQ8 = 4096;
    variants[3].boundaryErrorQ8 = 0;
    variants[3].errorMargin = 1;
    variants[4].boundaryErrorQ8 = 256;
    variants[4].errorMargin = 10;
    variants[5].tolerance = {1, 0};
    // A working range around the middle half of the depths the defaults keep: its limits cut
    // through the surface, so both sides of each are met.
    {
      std::vector<std::uint16_t> z(stripe.size());
      std::vector<std::uint8_t> c(stripe.size());
      ASSERT_TRUE(triangulateTrusted(*t, stripePlane, *DepthPlane::packed(z, w, h),
                                     *ImageView<std::uint8_t>::packed(c, w, h), defaults));
      std::erase(z, kNoDepth);
      ASSERT_GT(z.size(), stripe.size() / 4);
      std::ranges::sort(z);
      variants.push_back(defaults);
      variants.back().nearUnits = z[z.size() / 4];
      variants.back().farUnits = z[3 * z.size() / 4];
    }
    for (std::size_t v = 0; v < variants.size(); ++v) {
      SCOPED_TRACE((distorted ? "distorted, parameters " : "undistorted, parameters ") +
                   std::to_string(v));
      std::vector<std::uint16_t> depth(stripe.size(), 1234);
      std::vector<std::uint8_t> confidence(stripe.size(), 7);
      std::vector<std::uint16_t> depthReference(stripe.size(), 4321);
      std::vector<std::uint8_t> confidenceReference(stripe.size(), 9);
      ASSERT_TRUE(t->run(stripePlane, *DepthPlane::packed(depthReference, w, h)));
      ASSERT_TRUE(trustDepth(*t, stripePlane, *DepthPlane::packed(depthReference, w, h),
                             *ImageView<std::uint8_t>::packed(confidenceReference, w, h),
                             variants[v]));
      const test::AllocationCounter counter;
      ASSERT_TRUE(triangulateTrusted(*t, stripePlane, *DepthPlane::packed(depth, w, h),
                                     *ImageView<std::uint8_t>::packed(confidence, w, h),
                                     variants[v]));
      EXPECT_EQ(counter.allocations(), 0U);
      EXPECT_EQ(depth, depthReference);
      EXPECT_EQ(confidence, confidenceReference);
      const auto kept = std::count_if(depthReference.begin(), depthReference.end(),
                                      [](std::uint16_t z) { return z != kNoDepth; });
      if (v == 0 || v == 1 || v == 3) {  // the others keep (next to) nothing by design
        EXPECT_GT(kept, w * h / 4);
      }
      if (v == 6) {  // half the depths, and none outside the range
        EXPECT_GT(kept, w * h / 8);
        for (const std::uint16_t z : depthReference) {
          EXPECT_TRUE(z == kNoDepth || (z >= variants[v].nearUnits && z <= variants[v].farUnits));
        }
      }
    }
    std::vector<std::uint16_t> small(static_cast<std::size_t>((w - 1) * h));
    std::vector<std::uint8_t> confidence(stripe.size());
    const auto r = triangulateTrusted(*t, stripePlane, *DepthPlane::packed(small, w - 1, h),
                                      *ImageView<std::uint8_t>::packed(confidence, w, h), defaults);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::kSizeMismatch);
  }
}

// An undistorted projector keeps the closed form (the tests above): one shared numerator, and
// a nominal depth changes nothing.
TEST(DistortedProjector, UndistortedTablesDoNotDependOnTheWorkingRange) {
  const Rig rig = makeRig();
  const auto plain = buildTriangulationTables(rig, 0, 0, kDefaultDepthUnitM);
  const auto ranged = buildTriangulationTables(rig, 0, 0, kDefaultDepthUnitM, 0.3);
  ASSERT_TRUE(plain && ranged);
  EXPECT_TRUE(ranged->numerators.empty());
  EXPECT_EQ(ranged->numeratorBase, plain->numeratorBase);
  EXPECT_EQ(ranged->numeratorSlope, plain->numeratorSlope);
  EXPECT_EQ(ranged->denominatorBase, plain->denominatorBase);
  EXPECT_EQ(ranged->denominatorSlope, plain->denominatorSlope);
  EXPECT_EQ(ranged->sense, plain->sense);
  EXPECT_EQ(*Triangulator::workspaceBytes(*plain), *Triangulator::workspaceBytes(320, 240));
}

// The per-pixel numerators need their own arena space: the undistorted size is refused.
TEST(DistortedProjector, TablesNeedTheirOwnWorkspace) {
  Rig rig = makeRig();
  rig.projectors[0].dist = {0.02, 0.0, 0.0, 0.0, 0.0};
  const auto tables = buildTriangulationTables(rig, 0, 0, kDefaultDepthUnitM, kNominalM);
  ASSERT_TRUE(tables) << tables.error();
  const std::size_t plain = *Triangulator::workspaceBytes(320, 240);
  EXPECT_GE(*Triangulator::workspaceBytes(*tables), plain + 32U * 320U * 240U);
  std::vector<std::byte> memory(plain);
  Arena arena(memory);
  EXPECT_FALSE(Triangulator::create(*tables, arena));
  TriangulationTables torn = *tables;
  torn.numerators.pop_back();
  std::vector<std::byte> enough;
  const auto t = triangulatorFor(torn, enough);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code, Errc::kSizeMismatch);
}

// A lens the fit cannot follow to 0.1 mm at the nominal depth is refused, by its measured
// residual, naming the projector; a distorted projector needs a working range.
TEST(DistortedProjector, TooStrongDistortionIsRefusedNamingTheProjector) {
  Rig rig = makeRig();
  rig.projectors[0].dist = {-0.4, 0.0, 0.0, 0.0, 0.0};
  const auto tables = buildTriangulationTables(rig, 0, 0, kDefaultDepthUnitM, kNominalM);
  ASSERT_FALSE(tables);
  EXPECT_NE(tables.error().find("proj0"), std::string::npos) << tables.error();
  EXPECT_NE(tables.error().find("0.1 mm"), std::string::npos) << tables.error();
  EXPECT_NE(tables.error().find("nominal depth 0.9 m"), std::string::npos) << tables.error();

  const auto unranged = buildTriangulationTables(rig, 0, 0, kDefaultDepthUnitM);
  ASSERT_FALSE(unranged);
  EXPECT_NE(unranged.error().find("proj0"), std::string::npos) << unranged.error();
  EXPECT_FALSE(buildTriangulationTables(rig, 0, 0, kDefaultDepthUnitM, 0.0));
  EXPECT_FALSE(buildTriangulationTables(rig, 0, 0, kDefaultDepthUnitM, -1.0));
}

TEST(TriangulationTables, BadIndicesAndUnitsAreRejected) {
  const Rig rig = makeRig();
  EXPECT_FALSE(buildTriangulationTables(rig, 1, 0, kDefaultDepthUnitM));
  EXPECT_FALSE(buildTriangulationTables(rig, 0, 1, kDefaultDepthUnitM));
  EXPECT_FALSE(buildTriangulationTables(rig, 0, 0, 0.0));
  EXPECT_FALSE(buildTriangulationTables(rig, 0, 0, -1e-4));
}

TEST(TriangulationTables, BaselineIsTheDistanceBetweenCentres) {
  const Rig rig = makeRig();
  EXPECT_NEAR(baselineM(rig, 0, 0), std::hypot(0.25, 0.1), 1e-12);
}

// A coarser unit gives the same geometry: 1 mm units at 1.2345 m read 1235 (rounded half up
// of 1234.5 would be 1235; the tables make it 1234 or 1235, never further off).
TEST(TriangulationTables, DepthUnitScalesTheOutput) {
  const Rig rig = makeRig();
  const auto tables = buildTriangulationTables(rig, 0, 0, 0.001);
  ASSERT_TRUE(tables);
  std::vector<std::byte> memory(*Triangulator::workspaceBytes(320, 240));
  Arena arena(memory);
  const auto t = Triangulator::create(*tables, arena);
  ASSERT_TRUE(t);
  const Sample s = sampleAt(rig, 150, 100, 1.2346);
  ASSERT_TRUE(s.stripe);
  EXPECT_EQ(t->depthAt(150, 100, q16(*s.stripe)), 1235);
}

}  // namespace
}  // namespace smx::algo
