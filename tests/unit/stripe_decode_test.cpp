// Multi-layer decoding on synthetic boundary maps whose stripe coordinate is known exactly: a
// pattern of period periodPx along angle θ, s(x, y) = s0 + (x, y)·u / periodPx.
#include "smx/algo/stripe_decode.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "alloc_counter.hpp"
#include "smx/algo/stripe_code.hpp"

namespace smx::algo {
namespace {

struct Synthetic {
  int width = 160;
  int height = 96;
  double angleDeg = 0;
  double periodPx = 5.0;
  double s0 = 20.25;
  std::vector<Boundary> boundaries;
  std::vector<std::uint16_t> directions;

  [[nodiscard]] double ux() const { return std::cos(angleDeg * std::numbers::pi / 180); }
  [[nodiscard]] double uy() const { return std::sin(angleDeg * std::numbers::pi / 180); }
  [[nodiscard]] double s(int x, int y) const { return s0 + (x * ux() + y * uy()) / periodPx; }
  [[nodiscard]] Boundary& at(int x, int y) {
    return boundaries[static_cast<std::size_t>(y * width + x)];
  }

  // Each pixel owns the level k whose line lies within [−½, ½) px of its centre along u.
  void draw() {
    boundaries.assign(static_cast<std::size_t>(width * height), Boundary{});
    const auto raw = static_cast<std::uint16_t>(std::lround(angleDeg / 360.0 * 65536.0) & 0xFFFF);
    directions.assign(static_cast<std::size_t>(width * height), raw);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        place(x, y, s(x, y), [](int) { return true; });
      }
    }
  }

  // Moves boundary curve k to where s = k + stripes: a curve of the right level in the wrong
  // place, as a mislocated or a skipped boundary leaves it.
  void displace(int k, double stripes) {
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        if (at(x, y).present() && std::floor(s(x, y) + 0.5) == k) {
          at(x, y) = Boundary{};
        }
      }
    }
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        place(x, y, s(x, y) - stripes, [k](int level) { return level == k; });
      }
    }
  }

  // The boundary at (x, y) when the level nearest to `sv` lies within [−½, ½) px of its centre.
  template <class Keep>
  void place(int x, int y, double sv, Keep keep) {
    const int k = static_cast<int>(std::floor(sv + 0.5));
    const double deltaPx = (k - sv) * periodPx;
    if (k < 1 || k >= stripe::kStripes || deltaPx < -0.5 || deltaPx >= 0.5 || !keep(k)) {
      return;
    }
    Boundary& b = at(x, y);
    b.offset = static_cast<std::int16_t>(std::lround(deltaPx * 256));
    b.transition =
        Boundary::code(stripe::transitionBetween(stripe::kSequence[static_cast<std::size_t>(k - 1)],
                                                 stripe::kSequence[static_cast<std::size_t>(k)]));
    b.confidence = 255;
  }

  [[nodiscard]] ConstBoundaryPlane boundaryPlane() const {
    return *ConstBoundaryPlane::packed(boundaries, width, height);
  }
  [[nodiscard]] ConstDirectionPlane directionPlane() const {
    return *ConstDirectionPlane::packed(directions, width, height);
  }
};

struct Decoded {
  std::vector<StripeQ16> stripe;
  std::vector<std::int16_t> levels;
  DecodeStats stats;
};

Decoded decode(const Synthetic& syn, const DecodeParams& params = {}) {
  std::vector<std::byte> memory(*StripeDecoder::workspaceBytes(syn.width, syn.height, params));
  Arena arena(memory);
  auto decoder = StripeDecoder::create(syn.width, syn.height, params, arena);
  EXPECT_TRUE(decoder);
  Decoded out;
  out.stripe.assign(static_cast<std::size_t>(syn.width * syn.height), 0);
  auto plane = *StripePlane::packed(out.stripe, syn.width, syn.height);
  EXPECT_TRUE(decoder->run(syn.boundaryPlane(), syn.directionPlane(), plane));
  for (int y = 0; y < syn.height; ++y) {
    for (int x = 0; x < syn.width; ++x) {
      out.levels.push_back(decoder->levels().rowPtr(y)[x]);
    }
  }
  out.stats = decoder->stats();
  return out;
}

struct Errors {
  int decoded = 0;
  int wrong = 0;  // |s − s_true| > 0.01 stripe
  double maxAbs = 0;
};

Errors compare(const Synthetic& syn, const Decoded& d) {
  Errors e;
  for (int y = 0; y < syn.height; ++y) {
    for (int x = 0; x < syn.width; ++x) {
      const StripeQ16 v = d.stripe[static_cast<std::size_t>(y * syn.width + x)];
      if (v == kNoStripe) {
        continue;
      }
      ++e.decoded;
      const double err = std::abs(v / 65536.0 - syn.s(x, y));
      e.maxAbs = std::max(e.maxAbs, err);
      e.wrong += err > 0.01 ? 1 : 0;
    }
  }
  return e;
}

TEST(StripeDecode, CleanPatternGivesTheExactCoordinateEverywhereBetweenDecodableBoundaries) {
  for (const double angle : {0.0, 90.0, 30.0, 137.0, 200.0}) {
    Synthetic syn;
    syn.angleDeg = angle;
    syn.s0 = angle >= 180 ? 150.4 : 20.25;  // the stripe index decreases to the top-left
    syn.draw();
    const Decoded d = decode(syn);
    const Errors e = compare(syn, d);
    EXPECT_EQ(e.wrong, 0) << angle << "°: max error " << e.maxAbs << " stripe";
    // Every pixel more than two periods and the longest gap (maxGapPx) from the border has a
    // coordinate.
    int inner = 0;
    int innerDecoded = 0;
    for (int y = 12; y < syn.height - 12; ++y) {
      for (int x = 12; x < syn.width - 12; ++x) {
        ++inner;
        innerDecoded += d.stripe[static_cast<std::size_t>(y * syn.width + x)] != kNoStripe ? 1 : 0;
      }
    }
    EXPECT_GE(innerDecoded * 1000, inner * 998) << angle << "°";
    if (std::getenv("SMX_DUMP") != nullptr && innerDecoded != inner) {
      for (int y = 20; y < 40; ++y) {
        for (int x = 20; x < 70; ++x) {
          const auto i = static_cast<std::size_t>(y * syn.width + x);
          char c = d.stripe[i] == kNoStripe ? '.' : 'o';
          if (syn.at(x, y).present())
            c = d.levels[i] != 0 ? 'B' : 'b';
          std::putchar(c);
        }
        std::putchar('\n');
      }
    }
  }
}

TEST(StripeDecode, LevelsAreTheBoundaryIndexOfTheSequence) {
  Synthetic syn;
  syn.draw();
  const Decoded d = decode(syn);
  int checked = 0;
  for (int y = 0; y < syn.height; ++y) {
    for (int x = 0; x < syn.width; ++x) {
      const auto level = d.levels[static_cast<std::size_t>(y * syn.width + x)];
      if (level != 0) {
        EXPECT_EQ(level, static_cast<int>(std::floor(syn.s(x, y) + 0.5))) << x << "," << y;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 0);
  EXPECT_EQ(checked, d.stats.decodedPixels);
}

TEST(StripeDecode, NeverInterpolatesAcrossAMissingBoundary) {
  // Given a clean pattern with one boundary curve erased over the lower half
  Synthetic syn;
  syn.draw();
  const int erasedLevel = 30;
  for (int y = syn.height / 2; y < syn.height; ++y) {
    for (int x = 0; x < syn.width; ++x) {
      if (syn.at(x, y).present() && std::floor(syn.s(x, y) + 0.5) == erasedLevel) {
        syn.at(x, y) = Boundary{};
      }
    }
  }
  // When decoded
  const Decoded d = decode(syn);
  // Then nothing is wrong, the upper half still decodes between levels 29 and 31, and the lower
  // half has no coordinate there (the gap is two stripes wide, and its boundaries do not chain).
  EXPECT_EQ(compare(syn, d).wrong, 0);
  int upper = 0;
  for (int y = 0; y < syn.height; ++y) {
    for (int x = 0; x < syn.width; ++x) {
      const double sv = syn.s(x, y);
      if (sv < erasedLevel - 1 + 0.1 || sv > erasedLevel + 1 - 0.1) {
        continue;
      }
      const StripeQ16 v = d.stripe[static_cast<std::size_t>(y * syn.width + x)];
      if (y >= syn.height / 2) {
        EXPECT_EQ(v, kNoStripe) << x << "," << y;
      } else {
        upper += v != kNoStripe ? 1 : 0;
      }
    }
  }
  EXPECT_GT(upper, 0);
}

TEST(StripeDecode, CurvesOutvoteMisclassifiedPixelsThatScanLinesGetWrong) {
  // Given a pattern in which every 4th row of one boundary curve carries a wrong class that
  // still chains with one neighbour (so scan lines decode some windows to other levels)
  Synthetic syn;
  syn.draw();
  int flipped = 0;
  for (int y = 0; y < syn.height; y += 4) {
    for (int x = 0; x < syn.width; ++x) {
      Boundary& b = syn.at(x, y);
      if (b.present() && std::floor(syn.s(x, y) + 0.5) == 40) {
        b.transition = Boundary::code(stripe::reversed(b.kind()));
        ++flipped;
      }
    }
  }
  ASSERT_GT(flipped, 0);
  DecodeParams lines;
  lines.curves = false;
  const Errors withLines = compare(syn, decode(syn, lines));
  const Errors withCurves = compare(syn, decode(syn));
  // Then curves decode no wrong coordinate, and at least as many pixels as scan lines.
  EXPECT_EQ(withCurves.wrong, 0);
  EXPECT_GE(withCurves.decoded, withLines.decoded);
}

TEST(StripeDecode, DropsACurveSpacedUnlikeItsNeighbours) {
  // Given a clean pattern (period 5 px) in which boundary 40 lies 0.45 stripe ahead of its place
  // (gaps of 1.45 and 0.55 periods on either side; the colours still chain)
  Synthetic syn;
  syn.angleDeg = 20;
  syn.draw();
  const Decoded clean = decode(syn);
  const int moved = 40;
  syn.displace(moved, 0.45);
  // When decoded with the spacing check and without it
  DecodeParams unchecked;
  unchecked.maxGapRatioPct = 0;
  const Decoded d = decode(syn);
  const Decoded off = decode(syn, unchecked);
  // Then without it the stripes beside the curve are off by up to 0.45 stripe; with it no
  // coordinate is off by more than 0.1 stripe from the truth
  const auto wrongBy = [&](const Decoded& out, double tolerance) {
    int n = 0;
    for (int y = 0; y < syn.height; ++y) {
      for (int x = 0; x < syn.width; ++x) {
        const StripeQ16 v = out.stripe[static_cast<std::size_t>(y * syn.width + x)];
        n += v != kNoStripe && std::abs(v / 65536.0 - syn.s(x, y)) > tolerance ? 1 : 0;
      }
    }
    return n;
  };
  EXPECT_GT(wrongBy(off, 0.1), 100);
  EXPECT_EQ(wrongBy(d, 0.1), 0);
  // and the stripes two or more away from the moved curve keep every coordinate they had
  const auto decodedAway = [&](const Decoded& out) {
    int n = 0;
    for (int y = 0; y < syn.height; ++y) {
      for (int x = 0; x < syn.width; ++x) {
        const double sv = syn.s(x, y);
        const bool away = sv < moved - 2 || sv >= moved + 2;
        n += away && out.stripe[static_cast<std::size_t>(y * syn.width + x)] != kNoStripe ? 1 : 0;
      }
    }
    return n;
  };
  EXPECT_EQ(decodedAway(d), decodedAway(clean));
  EXPECT_LT(d.stats.decodedPixels, clean.stats.decodedPixels);
}

// Boundary positions with independent noise (±0.25 px uniform along the axis): averaging each
// along its curve (positionRadiusPx 2) brings the coordinate closer to the truth than the raw
// positions (0).
TEST(StripeDecode, AveragingAlongTheCurveReducesPositionNoise) {
  Synthetic syn;
  syn.angleDeg = 25;
  syn.draw();
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> noise(-64, 64);
  for (auto& b : syn.boundaries) {
    if (b.present()) {
      b.offset = static_cast<std::int16_t>(std::clamp(b.offset + noise(rng), -128, 128));
    }
  }
  const auto rms = [&](const Decoded& d) {
    double sum2 = 0;
    int n = 0;
    for (int y = 0; y < syn.height; ++y) {
      for (int x = 0; x < syn.width; ++x) {
        const StripeQ16 v = d.stripe[static_cast<std::size_t>(y * syn.width + x)];
        if (v != kNoStripe) {
          const double e = v / 65536.0 - syn.s(x, y);
          sum2 += e * e;
          ++n;
        }
      }
    }
    return std::sqrt(sum2 / n);
  };
  DecodeParams raw;
  raw.positionRadiusPx = 0;
  const double before = rms(decode(syn, raw));
  const double after = rms(decode(syn));
  EXPECT_LT(after, 0.7 * before) << before << " -> " << after << " stripe";
}

TEST(StripeDecode, RunsWithoutTouchingTheHeap) {
  Synthetic syn;
  syn.angleDeg = 60;
  syn.draw();
  const DecodeParams params;
  std::vector<std::byte> memory(*StripeDecoder::workspaceBytes(syn.width, syn.height, params));
  Arena arena(memory);
  auto decoder = StripeDecoder::create(syn.width, syn.height, params, arena);
  ASSERT_TRUE(decoder);
  std::vector<StripeQ16> stripe(static_cast<std::size_t>(syn.width * syn.height));
  auto plane = *StripePlane::packed(stripe, syn.width, syn.height);
  const test::AllocationCounter counter;
  ASSERT_TRUE(decoder->run(syn.boundaryPlane(), syn.directionPlane(), plane));
  EXPECT_EQ(counter.allocations(), 0U);
  EXPECT_LE(arena.highWater(), memory.size());
}

TEST(StripeDecode, RejectsPlanesOfAnotherSizeAndBadParameters) {
  Synthetic syn;
  syn.draw();
  std::vector<std::byte> memory(*StripeDecoder::workspaceBytes(syn.width, syn.height));
  Arena arena(memory);
  auto decoder = StripeDecoder::create(syn.width, syn.height, {}, arena);
  ASSERT_TRUE(decoder);
  std::vector<StripeQ16> stripe(static_cast<std::size_t>((syn.width - 1) * syn.height));
  auto small = *StripePlane::packed(stripe, syn.width - 1, syn.height);
  const auto r = decoder->run(syn.boundaryPlane(), syn.directionPlane(), small);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, Errc::kSizeMismatch);

  DecodeParams bad;
  bad.maxGapPx = 0;
  EXPECT_FALSE(StripeDecoder::workspaceBytes(syn.width, syn.height, bad));
  for (const auto& [field, value] : {std::pair{&DecodeParams::maxNeighbourDisagreePct, 101},
                                     std::pair{&DecodeParams::maxGapRatioPct, 99}}) {
    DecodeParams p;
    p.*field = value;
    const auto sized = StripeDecoder::workspaceBytes(syn.width, syn.height, p);
    ASSERT_FALSE(sized) << value;
    EXPECT_EQ(sized.error().code, Errc::kInvalidArgument);
  }
}

}  // namespace
}  // namespace smx::algo
