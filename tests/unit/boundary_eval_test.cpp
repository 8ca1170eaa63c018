#include "smx/eval/boundary_eval.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "smx/algo/boundary_map.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/stripe_code.hpp"

namespace smx::eval {
namespace {

using algo::Boundary;
using algo::ImageView;
namespace stripe = algo::stripe;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

std::size_t indexAt(int x, int y, int width) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
         static_cast<std::size_t>(x);
}

// The value, or one whose fields are NaN / −1, so that an absent value fails the comparisons.
StripeGradient orInvalid(const std::optional<StripeGradient>& g) {
  constexpr double kBad = std::numeric_limits<double>::quiet_NaN();
  return g.value_or(StripeGradient{.gx = kBad, .gy = kBad, .magnitude = kBad});
}
TrueBoundary orInvalid(const std::optional<TrueBoundary>& b) {
  return b.value_or(TrueBoundary{.level = -1,
                                 .deltaPx = std::numeric_limits<double>::quiet_NaN(),
                                 .transition = stripe::Transition::kPlusRG});
}

template <class T>
ImageView<const T> viewOf(const std::vector<T>& v, int w, int h) {
  return *ImageView<const T>::packed(v, w, h);
}

// s = a·x + b·y + c with the encoding direction at thetaDeg and stripes stripePx wide; s = c at
// the image centre. Computed here in double, independently of the code under test.
struct Field {
  double thetaDeg = 0;
  double stripePx = 4;
  double centreLevel = 100.137;
  int width = 64;
  int height = 48;
  std::function<bool(int, int)> hole = {};  // true: the projector does not light (x, y)

  [[nodiscard]] double a() const { return std::cos(thetaDeg * kDeg) / stripePx; }
  [[nodiscard]] double b() const { return std::sin(thetaDeg * kDeg) / stripePx; }
  [[nodiscard]] double at(int x, int y) const {
    return centreLevel + a() * (x - (width - 1) / 2.0) + b() * (y - (height - 1) / 2.0);
  }
  [[nodiscard]] bool lit(int x, int y) const { return !hole || !hole(x, y); }
};

struct Truth {
  int width = 0;
  int height = 0;
  std::vector<float> s;
  Mask region;  // lit

  [[nodiscard]] ImageView<const float> view() const { return viewOf(s, width, height); }
};

Truth makeTruth(const Field& f) {
  Truth t{.width = f.width, .height = f.height, .s = {}, .region = {}};
  t.region = Mask::filled(f.width, f.height, 0);
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const bool lit = f.lit(x, y);
      t.s.push_back(lit ? static_cast<float>(f.at(x, y)) : kNan);
      t.region.at(x, y) = lit ? 255 : 0;
    }
  }
  return t;
}

std::uint16_t rawOfDeg(double deg) {
  const double turns = deg / 360.0 - std::floor(deg / 360.0);
  return static_cast<std::uint16_t>(std::lround(turns * 65536.0) % 65536);
}

stripe::Transition transitionOfLevel(int k) {
  return stripe::transitionBetween(stripe::kSequence[static_cast<std::size_t>(k - 1)],
                                   stripe::kSequence[static_cast<std::size_t>(k)]);
}

struct Detections {
  int width = 0;
  int height = 0;
  std::vector<Boundary> boundaries;
  std::vector<std::uint16_t> direction;
  std::vector<int> level;  // the level each boundary was placed for, 0: none

  [[nodiscard]] ImageView<const Boundary> view() const { return viewOf(boundaries, width, height); }
  [[nodiscard]] ImageView<const std::uint16_t> directionView() const {
    return viewOf(direction, width, height);
  }
  Boundary& at(int x, int y) { return boundaries[indexAt(x, y, width)]; }
  [[nodiscard]] int count() const {
    int n = 0;
    for (const auto& b : boundaries) {
      n += b.present() ? 1 : 0;
    }
    return n;
  }
};

// What a perfect detector reports: at every lit pixel whose centre lies within half a pixel
// (along the encoding direction) before the nearest integer level, that level's boundary, moved by
// shiftPx along the encoding direction.
Detections perfectDetections(const Field& f, double shiftPx = 0) {
  Detections d{
      .width = f.width, .height = f.height, .boundaries = {}, .direction = {}, .level = {}};
  const std::size_t n = indexAt(0, f.height, f.width);
  d.boundaries.resize(n);
  d.direction.assign(n, rawOfDeg(f.thetaDeg));
  d.level.assign(n, 0);
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      if (!f.lit(x, y)) {
        continue;
      }
      const double s = f.at(x, y);
      const double k = std::round(s);
      const double deltaPx = (k - s) * f.stripePx;
      if (deltaPx < -0.5 || deltaPx >= 0.5 || k < 1 || k > 197) {
        continue;
      }
      const auto i = indexAt(x, y, f.width);
      d.boundaries[i] =
          Boundary{.offset = static_cast<std::int16_t>(std::lround((deltaPx + shiftPx) * 256.0)),
                   .transition = Boundary::code(transitionOfLevel(static_cast<int>(k))),
                   .confidence = 255};
      d.level[i] = static_cast<int>(k);
    }
  }
  return d;
}

BoundaryScore score(const Detections& d, const Truth& t, const ScoreOptions& options = {}) {
  return scoreBoundaries(d.view(), d.directionView(), t.view(), t.region.view(), options);
}

// ---------------------------------------------------------------------------------------------
// Truth gradient and ownership

TEST(BoundaryEvalTruth, GradientIsExactOnALinearPlaneIncludingBordersAndNextToHoles) {
  // Given a linear stripe plane with a NaN column at x = 10 and a NaN pixel pair around (20, 20)
  Field f{.thetaDeg = 60, .stripePx = 3.0};
  f.hole = [](int x, int y) { return x == 10 || ((x == 19 || x == 21) && y == 20); };
  const Truth t = makeTruth(f);
  // When the gradient is taken everywhere it is defined
  int defined = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const auto maybe = stripeGradient(t.view(), x, y);
      if (!f.lit(x, y) || (x == 20 && y == 20)) {
        // Then it is undefined on NaN and where both x neighbours are NaN
        EXPECT_FALSE(maybe.has_value()) << x << "," << y;
        continue;
      }
      // Then everywhere else (one-sided at the border and beside the holes) it is the plane's
      ASSERT_TRUE(maybe.has_value()) << x << "," << y;
      const StripeGradient g = orInvalid(maybe);
      ++defined;
      EXPECT_NEAR(g.gx, f.a(), 2e-5) << x << "," << y;
      EXPECT_NEAR(g.gy, f.b(), 2e-5) << x << "," << y;
      EXPECT_NEAR(g.magnitude, 1.0 / 3.0, 2e-5);
      EXPECT_NEAR(g.ux(), 0.5, 1e-4);
      EXPECT_NEAR(g.uy(), std::sqrt(3.0) / 2.0, 1e-4);
    }
  }
  EXPECT_EQ(defined, f.width * f.height - f.height - 3);
}

TEST(BoundaryEvalTruth, GradientIsCentralInsideAndOneSidedAtTheBorder) {
  // Given s = 50 + x²/16 + y/8 (exact in float): the central difference of x² is exactly 2x
  constexpr int kW = 8;
  constexpr int kH = 3;
  std::vector<float> s;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      s.push_back(static_cast<float>(50.0 + x * x / 16.0 + y / 8.0));
    }
  }
  for (int x = 1; x + 1 < kW; ++x) {
    const StripeGradient g = orInvalid(stripeGradient(viewOf(s, kW, kH), x, 1));
    EXPECT_DOUBLE_EQ(g.gx, x / 8.0) << x;
    EXPECT_DOUBLE_EQ(g.gy, 1.0 / 8.0);
  }
  // Then at the borders it is the one-sided difference
  EXPECT_DOUBLE_EQ(orInvalid(stripeGradient(viewOf(s, kW, kH), 0, 0)).gx, 1.0 / 16.0);
  EXPECT_DOUBLE_EQ(orInvalid(stripeGradient(viewOf(s, kW, kH), kW - 1, 2)).gx, 13.0 / 16.0);
}

TEST(BoundaryEvalTruth, ALevelHalfwayBetweenTwoPixelCentresHasOneOwner) {
  // Given s = 50.125 + x/4 (exact in float): level 51 lies at x = 3.5, δ = +0.5 from pixel 3
  // and −0.5 from pixel 4; the interval −½ ≤ δ < ½ gives it to pixel 4 only
  std::vector<float> s;
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 8; ++x) {
      s.push_back(static_cast<float>(50.125 + x / 4.0));
    }
  }
  std::vector<int> owners;
  for (int x = 0; x < 8; ++x) {
    if (const auto b = trueBoundaryAt(viewOf(s, 8, 2), x, 0); b && b->level == 51) {
      owners.push_back(x);
      EXPECT_DOUBLE_EQ(b->deltaPx, -0.5);
    }
  }
  EXPECT_EQ(owners, std::vector<int>{4});
}

TEST(BoundaryEvalTruth, FlatOrIsolatedPixelsHaveNoDirection) {
  const std::vector<float> flat(9, 50.0F);
  EXPECT_FALSE(stripeGradient(viewOf(flat, 3, 3), 1, 1).has_value());
  const std::vector<float> single = {42.3F};
  EXPECT_FALSE(stripeGradient(viewOf(single, 1, 1), 0, 0).has_value());
  EXPECT_FALSE(trueBoundaryAt(viewOf(single, 1, 1), 0, 0).has_value());
  EXPECT_FALSE(stripeGradient(viewOf(flat, 3, 3), 3, 1).has_value());  // outside
}

TEST(BoundaryEvalTruth, VerticalStripesOwnOnePixelPerLevelPerRow) {
  // Given s = 50.1 + x/4: level k is crossed at x = 4k − 200.4, so pixel x = 4k − 200 owns it
  // with δ = −0.4 px; levels 50..65 are owned inside x ∈ [0, 63].
  constexpr int kW = 64;
  constexpr int kH = 5;
  std::vector<float> s;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      s.push_back(static_cast<float>(50.1 + x / 4.0));
    }
  }
  int owners = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const auto maybe = trueBoundaryAt(viewOf(s, kW, kH), x, y);
      if (x <= 60 && x % 4 == 0) {
        ASSERT_TRUE(maybe.has_value()) << x;
        const TrueBoundary b = orInvalid(maybe);
        ++owners;
        EXPECT_EQ(b.level, (x + 200) / 4);
        EXPECT_NEAR(b.deltaPx, -0.4, 1e-4);
        EXPECT_EQ(b.transition, transitionOfLevel((x + 200) / 4));
      } else {
        EXPECT_FALSE(maybe.has_value()) << x;
      }
    }
  }
  EXPECT_EQ(owners, 16 * kH);
}

TEST(BoundaryEvalTruth, LevelsOutsideTheSequenceAreNotBoundaries) {
  // Given s running from −1.9 to 3.1 and from 195.1 to 200.1 along x (1 stripe per px, 2 rows)
  std::vector<float> low;
  std::vector<float> high;
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 6; ++x) {
      low.push_back(static_cast<float>(-1.9 + x));
      high.push_back(static_cast<float>(195.1 + x));
    }
  }
  // Then only levels 1..197 are owned
  std::vector<int> lowLevels;
  std::vector<int> highLevels;
  for (int x = 0; x < 6; ++x) {
    if (const auto b = trueBoundaryAt(viewOf(low, 6, 2), x, 0)) {
      lowLevels.push_back(b->level);
    }
    if (const auto b = trueBoundaryAt(viewOf(high, 6, 2), x, 0)) {
      highLevels.push_back(b->level);
    }
  }
  EXPECT_EQ(lowLevels, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(highLevels, (std::vector<int>{195, 196, 197}));
}

TEST(BoundaryEvalTruth, DirectionRawRoundTripsAndWraps) {
  EXPECT_EQ(directionRaw(0.0), 0);
  EXPECT_EQ(directionRaw(std::numbers::pi / 2), 16384);
  EXPECT_EQ(directionRaw(-std::numbers::pi / 2), 49152);
  EXPECT_EQ(directionRaw(2 * std::numbers::pi), 0);
  EXPECT_EQ(directionRaw(2 * std::numbers::pi - 1e-9), 0);
  EXPECT_NEAR(directionRadians(32768), std::numbers::pi, 1e-12);
  for (int raw = 0; raw < 65536; raw += 97) {
    EXPECT_EQ(directionRaw(directionRadians(static_cast<std::uint16_t>(raw))), raw);
  }
}

// ---------------------------------------------------------------------------------------------
// scoreBoundaries

struct DirectionCase {
  double thetaDeg;
  double stripePx;
};

class BoundaryEvalPerfect : public ::testing::TestWithParam<DirectionCase> {};

TEST_P(BoundaryEvalPerfect, ExactDetectionsScorePerfectly) {
  // Given a linear truth with a NaN disc and a NaN band, and a perfect detector
  Field f{.thetaDeg = GetParam().thetaDeg, .stripePx = GetParam().stripePx};
  f.hole = [](int x, int y) {
    return (x - 40) * (x - 40) + (y - 20) * (y - 20) < 64 || (y >= 30 && y < 33);
  };
  const Truth t = makeTruth(f);
  const Detections d = perfectDetections(f);
  // When scored
  const BoundaryScore s = score(d, t);
  // Then everything is found, in place, with the right class and sign
  EXPECT_EQ(s.detected, d.count());
  EXPECT_EQ(s.matched, s.detected);
  EXPECT_EQ(s.recalled, s.trueBoundaries);
  EXPECT_DOUBLE_EQ(s.recall, 1.0);
  EXPECT_DOUBLE_EQ(s.precision, 1.0);
  EXPECT_DOUBLE_EQ(s.classAccuracy, 1.0);
  EXPECT_EQ(s.classCorrect, s.matched);
  EXPECT_LT(s.positionRmsPx, 0.003);
  EXPECT_LT(s.positionMaxAbsPx, 0.005);
  EXPECT_EQ(s.wrongDirectionSign, 0);
  EXPECT_EQ(s.detectedWithoutTruth, 0);
  EXPECT_EQ(s.invalidTransitions, 0);
  // And the true boundaries are one band of one pixel per stripe: area / stripe width
  const double expected = t.region.count() / f.stripePx;
  EXPECT_NEAR(s.trueBoundaries, expected, 0.08 * expected);
  EXPECT_GE(s.matchedAtOwner, s.matched - s.matched / 50);  // float vs double ties only
  int confusionTotal = 0;
  int confusionDiagonal = 0;
  for (std::size_t i = 0; i < s.confusion.size(); ++i) {
    for (std::size_t j = 0; j < s.confusion[i].size(); ++j) {
      confusionTotal += s.confusion[i][j];
      confusionDiagonal += i == j ? s.confusion[i][j] : 0;
    }
  }
  EXPECT_EQ(confusionTotal, s.matched);
  EXPECT_EQ(confusionDiagonal, s.matched);
}

INSTANTIATE_TEST_SUITE_P(Directions, BoundaryEvalPerfect,
                         ::testing::Values(DirectionCase{0, 4}, DirectionCase{90, 2.5},
                                           DirectionCase{45, 3}, DirectionCase{60, 6},
                                           DirectionCase{150, 2.5}, DirectionCase{217, 5},
                                           DirectionCase{-30, 3.5}));

TEST(BoundaryEvalScore, ShiftedDetectionsGiveThatPositionError) {
  for (const double shift : {0.3, -0.3}) {
    // Given every detection moved by `shift` px along the encoding direction
    const Field f{.thetaDeg = 60, .stripePx = 4};
    const Truth t = makeTruth(f);
    const BoundaryScore s = score(perfectDetections(f, shift), t);
    // Then all still match, with an error of `shift`
    ASSERT_GT(s.matched, 0);
    EXPECT_DOUBLE_EQ(s.precision, 1.0);
    EXPECT_DOUBLE_EQ(s.recall, 1.0);
    EXPECT_NEAR(s.positionRmsPx, 0.3, 0.003);
    EXPECT_NEAR(s.positionMeanPx, shift, 0.003);
    EXPECT_NEAR(s.positionMaxAbsPx, 0.3, 0.005);
  }
}

TEST(BoundaryEvalScore, DetectionsBeyondTheToleranceDoNotMatch) {
  // Given detections 1.2 px off
  const Field f{.thetaDeg = 30, .stripePx = 6};
  const Truth t = makeTruth(f);
  const Detections d = perfectDetections(f, 1.2);
  // Then at the default tolerance of 1 px nothing matches, at 1.5 px everything does
  const BoundaryScore strict = score(d, t);
  EXPECT_EQ(strict.detected, d.count());
  EXPECT_EQ(strict.matched, 0);
  EXPECT_DOUBLE_EQ(strict.precision, 0.0);
  EXPECT_DOUBLE_EQ(strict.recall, 0.0);
  const BoundaryScore loose = score(d, t, ScoreOptions{.tolerancePx = 1.5});
  EXPECT_EQ(loose.matched, loose.detected);
  EXPECT_NEAR(loose.positionRmsPx, 1.2, 0.003);
}

TEST(BoundaryEvalScore, ABoundaryReportedAtTheNeighbouringPixelStillMatches) {
  // Given vertical stripes and each boundary put on the pixel to its right (offset − 1 px)
  const Field f{.thetaDeg = 0, .stripePx = 5};
  const Truth t = makeTruth(f);
  const Detections exact = perfectDetections(f);
  Detections moved = exact;
  for (auto& b : moved.boundaries) {
    b = Boundary{};
  }
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x + 1 < f.width; ++x) {
      Boundary b = exact.boundaries[indexAt(x, y, f.width)];
      if (b.present()) {
        b.offset = static_cast<std::int16_t>(b.offset - 256);
        moved.at(x + 1, y) = b;
      }
    }
  }
  const BoundaryScore s = score(moved, t);
  // Then everything matches, none at its owner
  ASSERT_GT(s.detected, 0);
  EXPECT_EQ(s.matched, s.detected);
  EXPECT_EQ(s.matchedAtOwner, 0);
  EXPECT_DOUBLE_EQ(s.recall, 1.0);
  EXPECT_LT(s.positionRmsPx, 0.003);
}

TEST(BoundaryEvalScore, ABoundaryReportedTwoPixelsAwayDoesNotMatch) {
  // Given vertical stripes and each boundary put two pixels to its left (offset + 2 px): the
  // position is exact but the pixel is outside the owner's 3×3 neighbourhood
  const Field f{.thetaDeg = 0, .stripePx = 5};
  const Truth t = makeTruth(f);
  const Detections exact = perfectDetections(f);
  Detections moved = exact;
  for (auto& b : moved.boundaries) {
    b = Boundary{};
  }
  for (int y = 0; y < f.height; ++y) {
    for (int x = 2; x < f.width; ++x) {
      Boundary b = exact.boundaries[indexAt(x, y, f.width)];
      if (b.present()) {
        b.offset = static_cast<std::int16_t>(b.offset + 512);
        moved.at(x - 2, y) = b;
      }
    }
  }
  const BoundaryScore s = score(moved, t);
  // Then nothing matches
  ASSERT_GT(s.detected, 0);
  EXPECT_EQ(s.matched, 0);
  EXPECT_DOUBLE_EQ(s.recall, 0.0);
}

TEST(BoundaryEvalScore, WrongTransitionsLowerClassAccuracyByTheirFraction) {
  // Given every 7th detection (raster order) with another valid transition
  const Field f{.thetaDeg = 45, .stripePx = 3};
  const Truth t = makeTruth(f);
  Detections d = perfectDetections(f);
  int seen = 0;
  int changed = 0;
  for (auto& b : d.boundaries) {
    if (b.present() && seen++ % 7 == 0) {
      const int wrong = (static_cast<int>(b.kind()) + 1 + changed % 5) % stripe::kTransitions;
      b.transition = Boundary::code(static_cast<stripe::Transition>(wrong));
      ++changed;
    }
  }
  const BoundaryScore s = score(d, t);
  // Then class accuracy drops by exactly changed / matched; positions still match
  ASSERT_EQ(s.matched, seen);
  EXPECT_EQ(s.classCorrect, seen - changed);
  EXPECT_DOUBLE_EQ(s.classAccuracy, 1.0 - static_cast<double>(changed) / seen);
  EXPECT_DOUBLE_EQ(s.precision, 1.0);
  int offDiagonal = 0;
  for (std::size_t i = 0; i < s.confusion.size(); ++i) {
    for (std::size_t j = 0; j < s.confusion[i].size(); ++j) {
      offDiagonal += i != j ? s.confusion[i][j] : 0;
    }
  }
  EXPECT_EQ(offDiagonal, changed);
}

TEST(BoundaryEvalScore, InvalidTransitionCodesAreCountedAndNeverCorrect) {
  const Field f{.thetaDeg = 90, .stripePx = 4};
  const Truth t = makeTruth(f);
  Detections d = perfectDetections(f);
  int n = 0;
  for (auto& b : d.boundaries) {
    if (b.present()) {
      b.transition = n++ == 0 ? 7 : b.transition;
    }
  }
  const BoundaryScore s = score(d, t);
  EXPECT_EQ(s.invalidTransitions, 1);
  EXPECT_EQ(s.matched, n);
  EXPECT_EQ(s.classCorrect, n - 1);
}

TEST(BoundaryEvalScore, FlippedDirectionSignIsCounted) {
  // Given a detector that reads the axis backwards: direction + 180°, offset and transition
  // reversed (the same positions)
  const Field f{.thetaDeg = 120, .stripePx = 4};
  const Truth t = makeTruth(f);
  Detections d = perfectDetections(f);
  for (auto& raw : d.direction) {
    raw = static_cast<std::uint16_t>(raw + 32768);
  }
  for (auto& b : d.boundaries) {
    if (b.present()) {
      b.offset = static_cast<std::int16_t>(-b.offset);
      b.transition = Boundary::code(stripe::reversed(b.kind()));
    }
  }
  const BoundaryScore s = score(d, t);
  // Then every detection has the wrong sign, still sits on its boundary, and no class is right
  ASSERT_GT(s.detected, 0);
  EXPECT_EQ(s.wrongDirectionSign, s.detected);
  EXPECT_EQ(s.matched, s.detected);
  EXPECT_LT(s.positionRmsPx, 0.003);
  EXPECT_EQ(s.classCorrect, 0);
  EXPECT_DOUBLE_EQ(s.classAccuracy, 0.0);
}

TEST(BoundaryEvalScore, AMissingBoundaryLowersRecall) {
  // Given the detections of one level removed
  const Field f{.thetaDeg = 60, .stripePx = 2.5};
  const Truth t = makeTruth(f);
  Detections d = perfectDetections(f);
  constexpr int kRemoved = 100;
  int removed = 0;
  for (std::size_t i = 0; i < d.boundaries.size(); ++i) {
    if (d.level[i] == kRemoved) {
      d.boundaries[i] = Boundary{};
      ++removed;
    }
  }
  const BoundaryScore s = score(d, t);
  // Then recall drops by that level's share of the true boundaries; precision is untouched
  ASSERT_GT(removed, 10);
  EXPECT_EQ(s.trueBoundaries - s.recalled, removed);
  EXPECT_DOUBLE_EQ(s.recall, 1.0 - static_cast<double>(removed) / s.trueBoundaries);
  EXPECT_DOUBLE_EQ(s.precision, 1.0);
}

TEST(BoundaryEvalScore, ASpuriousDetectionMidStripeLowersPrecision) {
  // Given extra detections at pixels whose centre is within 0.1 stripe of a stripe's middle
  const Field f{.thetaDeg = 20, .stripePx = 6};
  const Truth t = makeTruth(f);
  Detections d = perfectDetections(f);
  const int real = d.count();
  int spurious = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const double s = f.at(x, y);
      if (std::abs(s - std::floor(s) - 0.5) < 0.1 && spurious < 40) {
        d.at(x, y) = Boundary{.offset = 0, .transition = 1, .confidence = 255};
        ++spurious;
      }
    }
  }
  const BoundaryScore s = score(d, t);
  // Then precision is real / (real + spurious); recall is untouched
  ASSERT_EQ(spurious, 40);
  EXPECT_EQ(s.detected, real + spurious);
  EXPECT_EQ(s.matched, real);
  EXPECT_DOUBLE_EQ(s.precision, static_cast<double>(real) / (real + spurious));
  EXPECT_DOUBLE_EQ(s.recall, 1.0);
}

TEST(BoundaryEvalScore, OnlyTheRegionCountsAndDetectionsWithoutTruthAreFalse) {
  // Given a truth with a NaN block, a region that is the right half plus the NaN block
  Field f{.thetaDeg = 0, .stripePx = 4};
  f.hole = [](int x, int y) { return x >= 40 && x < 48 && y < 8; };
  const Truth t = makeTruth(f);
  Mask region = Mask::filled(f.width, f.height, 0);
  for (int y = 0; y < f.height; ++y) {
    for (int x = f.width / 2; x < f.width; ++x) {
      region.at(x, y) = 255;
    }
  }
  Detections d = perfectDetections(f);
  int inRegion = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = f.width / 2; x < f.width; ++x) {
      inRegion += d.at(x, y).present() ? 1 : 0;
    }
  }
  // and one detection inside the NaN block
  d.at(43, 3) = Boundary{.offset = 0, .transition = 1, .confidence = 255};
  const BoundaryScore s =
      scoreBoundaries(d.view(), d.directionView(), t.view(), region.view(), ScoreOptions{});
  // Then only the region's detections and boundaries count, and the NaN one is false
  EXPECT_EQ(s.detected, inRegion + 1);
  EXPECT_EQ(s.detectedWithoutTruth, 1);
  EXPECT_EQ(s.matched, inRegion);
  EXPECT_DOUBLE_EQ(s.recall, 1.0);
  EXPECT_EQ(s.trueBoundaries, inRegion);
}

TEST(BoundaryEvalScore, EmptyInputsScoreOneWithZeroCounts) {
  const std::vector<float> nan(16, kNan);
  const std::vector<Boundary> none(16);
  const std::vector<std::uint16_t> dir(16, 0);
  const Mask all = Mask::filled(4, 4, 255);
  const BoundaryScore s =
      scoreBoundaries(viewOf(none, 4, 4), viewOf(dir, 4, 4), viewOf(nan, 4, 4), all.view());
  EXPECT_EQ(s.trueBoundaries, 0);
  EXPECT_EQ(s.detected, 0);
  EXPECT_DOUBLE_EQ(s.recall, 1.0);
  EXPECT_DOUBLE_EQ(s.precision, 1.0);
  EXPECT_DOUBLE_EQ(s.classAccuracy, 1.0);
  EXPECT_DOUBLE_EQ(s.positionRmsPx, 0.0);
}

TEST(BoundaryEvalScore, PlanesOfDifferentSizesAreRejected) {
  const std::vector<float> s(16, 1.0F);
  const std::vector<Boundary> b(15);
  const std::vector<std::uint16_t> dir(16, 0);
  const Mask all = Mask::filled(4, 4, 255);
  EXPECT_THROW(
      (void)scoreBoundaries(viewOf(b, 5, 3), viewOf(dir, 4, 4), viewOf(s, 4, 4), all.view()),
      std::invalid_argument);
  EXPECT_THROW(
      (void)scoreDirections(viewOf(dir, 4, 4), viewOf(s, 4, 4), Mask::filled(3, 4, 255).view()),
      std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// scoreDirections

TEST(BoundaryEvalDirections, ARotationErrorIsMeasured) {
  const Field f{.thetaDeg = 60, .stripePx = 4};
  const Truth t = makeTruth(f);
  const std::size_t n = indexAt(0, f.height, f.width);
  for (const double error : {3.0, -3.0}) {
    const std::vector<std::uint16_t> dir(n, rawOfDeg(f.thetaDeg + error));
    const AngleStats a = scoreDirections(viewOf(dir, f.width, f.height), t.view(), t.region.view());
    EXPECT_EQ(a.count, f.width * f.height);
    EXPECT_NEAR(a.medianDeg, 3.0, 0.01);
    EXPECT_NEAR(a.p95Deg, 3.0, 0.01);
    EXPECT_NEAR(a.maxDeg, 3.0, 0.01);
    EXPECT_DOUBLE_EQ(a.fractionOver90, 0.0);
  }
  const std::vector<std::uint16_t> flipped(n, rawOfDeg(f.thetaDeg + 180));
  const AngleStats a =
      scoreDirections(viewOf(flipped, f.width, f.height), t.view(), t.region.view());
  EXPECT_NEAR(a.medianDeg, 180.0, 0.01);
  EXPECT_NEAR(a.maxDeg, 180.0, 0.01);
  EXPECT_DOUBLE_EQ(a.fractionOver90, 1.0);
}

TEST(BoundaryEvalDirections, PercentilesInterpolateBetweenOrderStatistics) {
  // Given a 10×10 region whose pixels have errors of 0.5°, 1.5°, …, 99.5° (alternating sides),
  // and a NaN column outside it that must be ignored
  Field f{.thetaDeg = 200, .stripePx = 3, .centreLevel = 100.137, .width = 11, .height = 10};
  f.hole = [](int x, int) { return x == 10; };
  const Truth t = makeTruth(f);
  std::vector<std::uint16_t> dir(110, 0);
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 10; ++x) {
      const int i = y * 10 + x;
      const double error = i + 0.5;
      dir[indexAt(x, y, 11)] = rawOfDeg(f.thetaDeg + (i % 2 == 0 ? error : -error));
    }
  }
  const AngleStats a = scoreDirections(viewOf(dir, 11, 10), t.view(), t.region.view());
  // Then median = sorted[49.5] = 50, p95 = sorted[94.05] = 94.55, max 99.5, 10 % over 90°
  EXPECT_EQ(a.count, 100);
  EXPECT_NEAR(a.medianDeg, 50.0, 0.01);
  EXPECT_NEAR(a.p95Deg, 94.55, 0.01);
  EXPECT_NEAR(a.maxDeg, 99.5, 0.01);
  EXPECT_DOUBLE_EQ(a.fractionOver90, 0.1);
}

// ---------------------------------------------------------------------------------------------
// Regions

Mask maskFrom(int w, int h, const std::vector<int>& bits) {
  Mask m = Mask::filled(w, h, 0);
  for (std::size_t i = 0; i < bits.size(); ++i) {
    m.pixels[i] = bits[i] != 0 ? 255 : 0;
  }
  return m;
}

std::vector<int> bitsOf(const Mask& m) {
  std::vector<int> out;
  out.reserve(m.pixels.size());
  for (const auto p : m.pixels) {
    out.push_back(p != 0 ? 1 : 0);
  }
  return out;
}

TEST(BoundaryEvalRegion, LitByExactlyAndAtLeastCountProjectors) {
  const Mask p0 = maskFrom(4, 1, {1, 1, 1, 0});
  const Mask p1 = maskFrom(4, 1, {1, 1, 0, 0});
  const Mask p2 = maskFrom(4, 1, {1, 0, 0, 0});
  const std::array lits = {p0.view(), p1.view(), p2.view()};
  EXPECT_EQ(bitsOf(litByExactly(lits, 0)), (std::vector<int>{0, 0, 0, 1}));
  EXPECT_EQ(bitsOf(litByExactly(lits, 1)), (std::vector<int>{0, 0, 1, 0}));
  EXPECT_EQ(bitsOf(litByExactly(lits, 2)), (std::vector<int>{0, 1, 0, 0}));
  EXPECT_EQ(bitsOf(litByExactly(lits, 3)), (std::vector<int>{1, 0, 0, 0}));
  EXPECT_EQ(bitsOf(litByAtLeast(lits, 2)), (std::vector<int>{1, 1, 0, 0}));
  EXPECT_EQ(bitsOf(litByAtLeast(lits, 1)), (std::vector<int>{1, 1, 1, 0}));
  EXPECT_EQ(litByAtLeast(lits, 2).view().width(), 4);
  EXPECT_EQ(litByExactly({}, 1).count(), 0);
  const Mask other = Mask::filled(3, 1, 255);
  const std::array mismatched = {p0.view(), other.view()};
  EXPECT_THROW((void)litByAtLeast(mismatched, 1), std::invalid_argument);
}

TEST(BoundaryEvalRegion, ErodeRemovesPixelsNearHolesAndTheBorder) {
  // Given a full 7×7 mask: radius 1 keeps the inner 5×5, radius 2 the inner 3×3
  const Mask full = Mask::filled(7, 7, 255);
  EXPECT_EQ(erode(full, 0).count(), 49);
  EXPECT_EQ(erode(full, 1).count(), 25);
  EXPECT_EQ(erode(full, 2).count(), 9);
  EXPECT_EQ(erode(full, 1).at(0, 3), 0);
  EXPECT_EQ(erode(full, 1).at(1, 1), 255);
  // Given a hole at the centre of a 9×9 mask: radius 1 removes its 4-neighbours (distance 1) but
  // not its diagonals (√2)
  Mask holed = Mask::filled(9, 9, 255);
  holed.at(4, 4) = 0;
  const Mask e = erode(holed, 1);
  EXPECT_EQ(e.at(4, 4), 0);
  EXPECT_EQ(e.at(3, 4), 0);
  EXPECT_EQ(e.at(4, 5), 0);
  EXPECT_EQ(e.at(3, 3), 255);
  EXPECT_EQ(e.at(5, 5), 255);
  EXPECT_EQ(e.count(), 49 - 5);
  // And radius 2 removes the 13 pixels within distance 2 of it (the 5×5 disc of radius 2)
  EXPECT_EQ(erode(holed, 2).count(), 25 - 13);
}

TEST(BoundaryEvalRegion, SmoothOnlyRemovesOcclusionEdgesAndMissingDepth) {
  // Given depth 1.0 m on the left, 1.5 m from x = 4, a NaN at (7, 2), a gentle slope elsewhere
  constexpr int kW = 10;
  constexpr int kH = 5;
  std::vector<float> depth;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      depth.push_back(x == 7 && y == 2 ? kNan
                                       : static_cast<float>((x < 4 ? 1.0 : 1.5) + 0.001 * y));
    }
  }
  const Mask all = Mask::filled(kW, kH, 255);
  const Mask m = smoothOnly(all, viewOf(depth, kW, kH), 0.05);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const bool edge = x == 3 || x == 4;
      const bool nearNan = std::abs(x - 7) <= 1 && std::abs(y - 2) <= 1;
      EXPECT_EQ(m.at(x, y) != 0, !edge && !nearNan) << x << "," << y;
    }
  }
  // And pixels already out of the mask stay out
  Mask some = all;
  some.at(0, 0) = 0;
  EXPECT_EQ(smoothOnly(some, viewOf(depth, kW, kH), 0.05).at(0, 0), 0);
  // And a loose threshold keeps the step
  EXPECT_EQ(smoothOnly(all, viewOf(depth, kW, kH), 0.6).count(), kW * kH - 9);
}

}  // namespace
}  // namespace smx::eval
