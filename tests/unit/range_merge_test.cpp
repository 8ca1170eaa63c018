// The paper's median-variant merge (range_merge.hpp) on hand-worked windows, each built so that a
// plausible wrong rule gives another answer, and against a plain reference over random planes;
// the consistency vote before it on synthetic range planes with known depth (one projector
// offset in a patch); the depth-edge filter (depth_edges.hpp) that runs before the merge.
#include "smx/algo/range_merge.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <initializer_list>
#include <random>
#include <vector>

#include "alloc_counter.hpp"
#include "smx/algo/depth_edges.hpp"

namespace smx::algo {
namespace {

struct Plane {
  int width = 3;
  int height = 3;
  std::vector<std::uint16_t> z;

  explicit Plane(std::initializer_list<std::uint16_t> values, int w = 3, int h = 3)
      : width(w), height(h), z(values) {
    z.resize(static_cast<std::size_t>(w * h), 0);
  }
  [[nodiscard]] ConstDepthPlane view() const { return *ConstDepthPlane::packed(z, width, height); }
};

// Every value agrees with every other: the paper's filter alone, as the hand-worked windows
// below (whose values lie far apart) need.
constexpr DepthTolerance kPaperOnly{65535, 0};

// The merged value at (x, y) of the given range images, the paper's filter alone.
std::uint16_t mergedAt(const std::vector<const Plane*>& inputs, int x = 1, int y = 1) {
  std::vector<ConstDepthPlane> views;
  for (const Plane* p : inputs) {
    views.push_back(p->view());
  }
  const int w = inputs[0]->width;
  const int h = inputs[0]->height;
  std::vector<std::uint16_t> out(static_cast<std::size_t>(w * h), 7);
  EXPECT_TRUE(mergeRanges(views, *DepthPlane::packed(out, w, h), kPaperOnly));
  return out[static_cast<std::size_t>(y * w + x)];
}

// Counts 9 against 5 (difference 4 > 3): the fuller set wins although its variance is larger.
// (With "≥ 3" or by variance alone the tight set's 2000 would come out.)
TEST(RangeMerge, ACountDifferenceOverThreePicksTheFullerSet) {
  const Plane full({1000, 1010, 1020, 1030, 1040, 1050, 1060, 1070, 1080});
  const Plane sparse({2000, 0, 2000, 0, 2000, 0, 2000, 0, 2000});
  EXPECT_EQ(mergedAt({&full, &sparse}), 1040);
  EXPECT_EQ(mergedAt({&sparse, &full}), 1040);
}

// Counts 9 against 6 (difference exactly 3): the variance decides, and the tight set wins.
TEST(RangeMerge, ACountDifferenceOfThreeLetsTheSmallerVarianceWin) {
  const Plane full({1000, 1010, 1020, 1030, 1040, 1050, 1060, 1070, 1080});
  const Plane tight({2000, 2001, 2000, 0, 2001, 0, 2000, 0, 2001});
  EXPECT_EQ(mergedAt({&full, &tight}), 2001);  // median of 2000 ×3, 2001 ×3: (2000 + 2001 + 1) / 2
  EXPECT_EQ(mergedAt({&tight, &full}), 2001);
}

// Equal variances: the median of both sets together, which is neither set's median nor the
// mean (1060) of the union.
TEST(RangeMerge, EqualVariancesTakeTheMedianOfBoth) {
  const Plane a({1000, 1000, 1000, 1000, 1090, 1000, 1000, 1000, 1000});
  const Plane b({1100, 1100, 1100, 1100, 1190, 1100, 1100, 1100, 1100});
  // union sorted: 1000 ×8, 1090, 1100 ×8, 1190 → middle pair 1090, 1100
  EXPECT_EQ(mergedAt({&a, &b}), 1095);
}

// A one-member set has the largest variance: a two-member set with a wide spread beats it.
TEST(RangeMerge, AOneMemberSetLosesToAnyWiderSet) {
  const Plane single({0, 0, 0, 0, 3000, 0, 0, 0, 0});
  const Plane pair({0, 0, 1000, 0, 0, 0, 5000, 0, 0});
  EXPECT_EQ(mergedAt({&single, &pair}), 3000);  // centre: only `single` is valid there...
  const Plane pairCentre({0, 0, 1000, 0, 5000, 0, 0, 0, 0});
  EXPECT_EQ(mergedAt({&single, &pairCentre}), 3000);  // (1000 + 5000 + 1) / 2 = 3000 too
  const Plane pairCentre2({0, 0, 1000, 0, 4000, 0, 0, 0, 0});
  EXPECT_EQ(mergedAt({&single, &pairCentre2}), 2500);  // the pair, not the single 3000
  // Two single members: equal (maximal) variances, both together.
  const Plane other({0, 0, 0, 0, 0, 0, 0, 0, 2001});
  EXPECT_EQ(mergedAt({&single, &other}), 2501);
}

// An empty set is never chosen; no value at the centre in any image: no output there.
TEST(RangeMerge, EmptySetsAreNeverChosenAndNothingGrowsIntoHoles) {
  const Plane some({0, 0, 0, 0, 1500, 1502, 0, 0, 0});
  const Plane none({});
  EXPECT_EQ(mergedAt({&none, &some}), 1501);
  EXPECT_EQ(mergedAt({&some, &none}), 1501);
  const Plane ring({1000, 1000, 1000, 1000, 0, 1000, 1000, 1000, 1000});
  EXPECT_EQ(mergedAt({&ring, &none}), kNoDepth);
  EXPECT_EQ(mergedAt({&ring}), kNoDepth);
}

// Three images: a left fold. The first two tie in variance (their union is taken), and the
// union (8 members) beats the third (4 members) on count: difference 4 > 3.
TEST(RangeMerge, ThreeImagesFoldFromTheLeft) {
  const Plane a({0, 0, 0, 1000, 1010, 1020, 0, 0, 1030});
  const Plane b({0, 0, 0, 2000, 2010, 2020, 0, 0, 2030});
  const Plane c({0, 0, 0, 0, 3000, 3000, 0, 3000, 3000});
  // a ∪ b sorted: 1000 1010 1020 1030 2000 2010 2020 2030 → (1030 + 2000 + 1) / 2
  EXPECT_EQ(mergedAt({&a, &b, &c}), 1515);
}

// At the border the window is clipped: a corner sees 2×2 pixels.
TEST(RangeMerge, BorderWindowsAreClipped) {
  const Plane a({1000, 1002, 0, 1004, 0, 0, 0, 0, 9000});
  EXPECT_EQ(mergedAt({&a}, 0, 0), 1002);  // {1000, 1002, 1004}; 9000 is outside the 2×2
}

TEST(RangeMerge, RejectsMismatchedSizesAndCounts) {
  const Plane a({});
  const Plane big({}, 4, 3);
  std::vector<std::uint16_t> out(9);
  const std::vector<ConstDepthPlane> mixed = {a.view(), big.view()};
  EXPECT_FALSE(mergeRanges(mixed, *DepthPlane::packed(out, 3, 3)));
  EXPECT_FALSE(mergeRanges({}, *DepthPlane::packed(out, 3, 3)));
  const std::vector<ConstDepthPlane> nine(9, a.view());
  EXPECT_FALSE(mergeRanges(nine, *DepthPlane::packed(out, 3, 3)));
  const std::vector<ConstDepthPlane> two = {a.view(), a.view()};
  std::vector<std::uint8_t> conf(9);
  const std::vector<ImageView<const std::uint8_t>> oneConfidence = {
      *ImageView<const std::uint8_t>::packed(conf, 3, 3)};
  EXPECT_FALSE(mergeRanges(two, oneConfidence, *DepthPlane::packed(out, 3, 3),
                           *ImageView<std::uint8_t>::packed(conf, 3, 3)));
  EXPECT_FALSE(mergeRanges(two, *DepthPlane::packed(out, 3, 3), DepthTolerance{50, 1001}));
}

// A plain reference: sets as vectors, variances from the deviations (not the sums of squares)
// compared exactly, the same fold, the median from a sort.
std::uint16_t reference(const std::vector<std::vector<std::uint16_t>>& planes, int w, int h, int x,
                        int y) {
  bool centre = false;
  for (const auto& p : planes) {
    centre = centre || p[static_cast<std::size_t>(y * w + x)] != 0;
  }
  if (!centre) {
    return 0;
  }
  std::vector<double> best;
  // Σ(n·z − Σz)² = n³·variance, exactly (the test's depths span 40 units: |n·z − Σz| ≤ 72·40,
  // so the products below stay under 2^48); a one-member set: the largest variance.
  using Wide = std::int64_t;
  const auto n3Variance = [](const std::vector<double>& v) {
    Wide sum = 0;
    for (double z : v) {
      sum += static_cast<Wide>(z);
    }
    Wide s = 0;
    for (double z : v) {
      const Wide d = static_cast<Wide>(v.size()) * static_cast<Wide>(z) - sum;
      s += d * d;
    }
    return s;
  };
  // −1: a has the smaller variance, 1: b, 0: equal.
  const auto compare = [&](const std::vector<double>& a, const std::vector<double>& b) {
    if (a.size() == 1 || b.size() == 1) {
      return a.size() == b.size() ? 0 : (a.size() == 1 ? 1 : -1);
    }
    const Wide na = static_cast<Wide>(a.size());
    const Wide nb = static_cast<Wide>(b.size());
    const Wide va = n3Variance(a) * nb * nb * nb;
    const Wide vb = n3Variance(b) * na * na * na;
    return va < vb ? -1 : (vb < va ? 1 : 0);
  };
  for (const auto& p : planes) {
    std::vector<double> set;
    for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy) {
      for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx) {
        if (p[static_cast<std::size_t>(yy * w + xx)] != 0) {
          set.push_back(p[static_cast<std::size_t>(yy * w + xx)]);
        }
      }
    }
    if (set.empty()) {
      continue;
    }
    const auto nb = static_cast<int>(best.size());
    const auto ns = static_cast<int>(set.size());
    if (best.empty() || ns - nb > 3) {
      best = set;
    } else if (nb - ns > 3) {
      continue;
    } else {
      const int c = compare(best, set);
      if (c > 0) {
        best = set;
      } else if (c == 0) {
        best.insert(best.end(), set.begin(), set.end());
      }
    }
  }
  std::sort(best.begin(), best.end());
  const std::size_t n = best.size();
  const double m = n % 2 == 1 ? best[n / 2] : std::floor((best[n / 2 - 1] + best[n / 2] + 1) / 2);
  return static_cast<std::uint16_t>(m);
}

// With the default tolerance (5 mm = 50 units) depths 5000…5040 all agree: the vote changes
// nothing and the output is the paper's filter's.
TEST(RangeMerge, MatchesAPlainReferenceOnRandomSparsePlanesWithoutTouchingTheHeap) {
  std::mt19937 rng(11);
  const int w = 37;
  const int h = 23;
  for (int trial = 0; trial < 20; ++trial) {
    const int count = 1 + trial % 3;
    std::vector<std::vector<std::uint16_t>> planes(static_cast<std::size_t>(count));
    std::uniform_int_distribution<int> present(0, 99);
    std::uniform_int_distribution<int> depth(5000, 5040);  // narrow: ties in variance happen
    for (auto& p : planes) {
      p.resize(static_cast<std::size_t>(w * h));
      const int density = 30 + 25 * (trial % 3);
      for (auto& z : p) {
        z = present(rng) < density ? static_cast<std::uint16_t>(depth(rng)) : 0;
      }
    }
    std::vector<ConstDepthPlane> views;
    for (const auto& p : planes) {
      views.push_back(*ConstDepthPlane::packed(p, w, h));
    }
    std::vector<std::uint16_t> out(static_cast<std::size_t>(w * h));
    const test::AllocationCounter counter;
    ASSERT_TRUE(mergeRanges(views, *DepthPlane::packed(out, w, h)));
    EXPECT_EQ(counter.allocations(), 0U);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        ASSERT_EQ(out[static_cast<std::size_t>(y * w + x)], reference(planes, w, h, x, y))
            << "trial " << trial << " at " << x << "," << y;
      }
    }
  }
}

// Synthetic range planes of a sloped surface with known depth (units of 0.1 mm, about 0.9 m) and
// ±3 units of noise; `offset` is added inside the patch [10, 20) × [8, 16) of the chosen planes.
struct Scene {
  static constexpr int kW = 32;
  static constexpr int kH = 24;
  std::vector<std::vector<std::uint16_t>> planes;

  [[nodiscard]] static int truth(int x, int y) { return 9000 + 3 * x + 2 * y; }
  [[nodiscard]] static bool inPatch(int x, int y) { return x >= 10 && x < 20 && y >= 8 && y < 16; }

  Scene(int count, const std::vector<int>& offsetPlanes, int offset) {
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> noise(-3, 3);
    for (int p = 0; p < count; ++p) {
      std::vector<std::uint16_t> z(static_cast<std::size_t>(kW * kH));
      const bool offsetHere =
          std::find(offsetPlanes.begin(), offsetPlanes.end(), p) != offsetPlanes.end();
      for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
          const int shift = offsetHere && inPatch(x, y) ? offset : 0;
          z[static_cast<std::size_t>(y * kW + x)] =
              static_cast<std::uint16_t>(truth(x, y) + noise(rng) + shift);
        }
      }
      planes.push_back(std::move(z));
    }
  }
  [[nodiscard]] std::vector<std::uint16_t> merge() const {
    std::vector<ConstDepthPlane> views;
    for (const auto& p : planes) {
      views.push_back(*ConstDepthPlane::packed(p, kW, kH));
    }
    std::vector<std::uint16_t> out(static_cast<std::size_t>(kW * kH), 7);
    EXPECT_TRUE(mergeRanges(views, *DepthPlane::packed(out, kW, kH)));
    return out;
  }
};

// A merged value is right when it is within the noise and the 3×3 window's slope of the truth
// (3 + 3 + 2 units); a blend of the 3 cm offset (300 units) into a median of at most 27 values
// moves it further, the offset itself by 300.
constexpr int kWindowSpread = 8;

// Three projectors, the third 3 cm off in the patch: the two that agree outvote it, everywhere.
TEST(RangeMerge, TwoAgreeingRangesOutvoteAThirdOffsetByThreeCentimetres) {
  const Scene scene(3, {2}, 300);
  const auto out = scene.merge();
  for (int y = 0; y < Scene::kH; ++y) {
    for (int x = 0; x < Scene::kW; ++x) {
      const int z = out[static_cast<std::size_t>(y * Scene::kW + x)];
      ASSERT_NE(z, kNoDepth) << x << "," << y;
      EXPECT_LE(std::abs(z - Scene::truth(x, y)), kWindowSpread) << x << "," << y;
    }
  }
}

// Two projectors that disagree in the patch: no depth there rather than a guess; outside it the
// depth is right, also in the ring where the window reaches into the patch.
TEST(RangeMerge, TwoRangesThatDisagreeGiveNoDepth) {
  for (const int offset : {300, -300, 110}) {  // 11 mm: beyond the tolerance, 1 % of z ≈ 9.1 mm
    const Scene scene(2, {1}, offset);
    const auto out = scene.merge();
    for (int y = 0; y < Scene::kH; ++y) {
      for (int x = 0; x < Scene::kW; ++x) {
        const int z = out[static_cast<std::size_t>(y * Scene::kW + x)];
        if (Scene::inPatch(x, y)) {
          EXPECT_EQ(z, kNoDepth) << offset << " at " << x << "," << y;
        } else {
          EXPECT_LE(std::abs(z - Scene::truth(x, y)), kWindowSpread)
              << offset << " at " << x << "," << y;
        }
      }
    }
  }
}

// Where one projector alone lights the surface its range passes, offset or not (the trust filter
// is what judges a pair on its own), and a neighbouring range that disagrees does not leak in.
TEST(RangeMerge, ARangeAlonePassesAndDisagreeingNeighboursStayOut) {
  Scene scene(2, {1}, 300);
  for (int y = 0; y < Scene::kH; ++y) {
    for (int x = 0; x < 15; ++x) {
      scene.planes[0][static_cast<std::size_t>(y * Scene::kW + x)] = kNoDepth;  // 1 alone
    }
  }
  const auto out = scene.merge();
  for (int y = 0; y < Scene::kH; ++y) {
    for (int x = 0; x < Scene::kW; ++x) {
      const int z = out[static_cast<std::size_t>(y * Scene::kW + x)];
      const int expected = Scene::truth(x, y) + (x < 15 && Scene::inPatch(x, y) ? 300 : 0);
      if (x >= 15 && Scene::inPatch(x, y)) {
        EXPECT_EQ(z, kNoDepth) << x << "," << y;
      } else {
        EXPECT_LE(std::abs(z - expected), kWindowSpread) << x << "," << y;
      }
    }
  }
}

// The merged confidence: the best agreeing range's predicted error divided by √k, 0 without
// depth. 3×3 planes, the values at the centre.
TEST(RangeMerge, ConfidenceRisesWhenRangesAgreeAndIsZeroWithoutDepth) {
  const auto at = [](const std::vector<std::uint16_t>& zs, const std::vector<std::uint8_t>& cs) {
    std::vector<std::vector<std::uint16_t>> planes;
    std::vector<std::vector<std::uint8_t>> conf;
    for (std::size_t i = 0; i < zs.size(); ++i) {
      planes.emplace_back(9, zs[i]);
      conf.emplace_back(9, cs[i]);
    }
    std::vector<ConstDepthPlane> views;
    std::vector<ImageView<const std::uint8_t>> confViews;
    for (std::size_t i = 0; i < zs.size(); ++i) {
      views.push_back(*ConstDepthPlane::packed(planes[i], 3, 3));
      confViews.push_back(*ImageView<const std::uint8_t>::packed(conf[i], 3, 3));
    }
    std::vector<std::uint16_t> out(9);
    std::vector<std::uint8_t> outConf(9, 7);
    EXPECT_TRUE(mergeRanges(views, confViews, *DepthPlane::packed(out, 3, 3),
                            *ImageView<std::uint8_t>::packed(outConf, 3, 3)));
    return static_cast<int>(outConf[4]);
  };
  EXPECT_EQ(at({9000}, {200}), 200);                             // alone: its own
  EXPECT_EQ(at({9000, 9010}, {200, 150}), 255 - 39);             // 55 · 181 / 256 = 38.9
  EXPECT_EQ(at({9000, 9010, 8990}, {200, 150, 100}), 255 - 32);  // 55 · 148 / 256 = 31.8
  EXPECT_EQ(at({9000, 9300, 9010}, {200, 255, 150}), 255 - 39);  // the outvoted one counts not
  EXPECT_EQ(at({9000, 9300}, {200, 255}), 0);                    // disagreeing: no depth
  EXPECT_EQ(at({0, 9000}, {0, 1}), 1);                           // never 0 where depth is
}

// The depth-edge filter: a 5×3 image with a step from 1000 to 1100 units (10 %) between columns
// 1 and 2 and a gentle ramp (1 % per pixel) elsewhere.
TEST(DepthEdges, DropsBothSidesOfAJumpAndKeepsSmoothSurfaces) {
  const int w = 5;
  const int h = 3;
  // row-major: columns 0–1 near (1000, 1010), columns 2–4 far (1100, 1111, 1122), a hole at (4, 0)
  const std::vector<std::uint16_t> in = {1000, 1010, 1100, 1111, 0,     //
                                         1000, 1010, 1100, 1111, 1122,  //
                                         1000, 1010, 1100, 1111, 1122};
  std::vector<std::uint16_t> out(in.size(), 7);
  ASSERT_TRUE(
      removeDepthEdges(*ConstDepthPlane::packed(in, w, h), *DepthPlane::packed(out, w, h), 20));
  // 2 %: column 1 (1010 beside 1100: 8.9 %) and column 2 (1100 beside 1010: 8.2 %) go; columns 0,
  // 3, 4 stay (their neighbours differ by ≤ 1 %); the hole stays a hole and is not an edge.
  const std::vector<std::uint16_t> expected = {1000, 0, 0, 1111, 0,     //
                                               1000, 0, 0, 1111, 1122,  //
                                               1000, 0, 0, 1111, 1122};
  EXPECT_EQ(out, expected);
  // At 10 % the step (8.2–8.9 %) stays; 0 copies unchanged.
  ASSERT_TRUE(
      removeDepthEdges(*ConstDepthPlane::packed(in, w, h), *DepthPlane::packed(out, w, h), 100));
  EXPECT_EQ(out, in);
  ASSERT_TRUE(
      removeDepthEdges(*ConstDepthPlane::packed(in, w, h), *DepthPlane::packed(out, w, h), 0));
  EXPECT_EQ(out, in);
  std::vector<std::uint16_t> small(4);
  EXPECT_FALSE(
      removeDepthEdges(*ConstDepthPlane::packed(in, w, h), *DepthPlane::packed(small, 2, 2), 20));
}

}  // namespace
}  // namespace smx::algo
