// Direct colour estimation (the baseline of docs/demux.md) on small synthetic images, host and
// aarch64: the hue rule, boundaries where a single clean pattern puts them (class, sub-pixel
// position, reading direction), input checks, no heap use, and, superposed, the brighter pattern
// read in place of both. Measured against demultiplexing on rendered scenes:
// direct_colour_accuracy_test.cpp.
#include "smx/algo/direct_colour.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numbers>
#include <span>
#include <utility>
#include <vector>

#include "alloc_counter.hpp"
#include "smx/algo/fixed_math.hpp"
#include "smx/algo/stripe_code.hpp"
#include "synthetic_stripes.hpp"

namespace smx::algo {
namespace {

using stripe::Colour;

TEST(DirectColourClassify, APrimaryIsItsDominantChannelWithItsSaturationAsConfidence) {
  const ColourClass r = classifyColour({200, 0, 0});
  EXPECT_TRUE(r.present);
  EXPECT_EQ(r.colour, Colour::kRed);
  EXPECT_EQ(r.confidence, 255);
  const ColourClass g = classifyColour({20, 200, 60});
  EXPECT_TRUE(g.present);
  EXPECT_EQ(g.colour, Colour::kGreen);
  EXPECT_EQ(g.confidence, 255 * 140 / 200);
  const ColourClass b = classifyColour({30, 20, 90});
  EXPECT_TRUE(b.present);
  EXPECT_EQ(b.colour, Colour::kBlue);
  EXPECT_EQ(b.confidence, 255 * 60 / 90);
}

TEST(DirectColourClassify, HueSectorsMeetAtTheSecondariesWhichGoToTheLaterPrimary) {
  // A yellow leaning to red is red, to green green; an exact secondary is the later primary of
  // R → G → B → R, with confidence 0.
  EXPECT_EQ(classifyColour({150, 149, 20}).colour, Colour::kRed);
  EXPECT_EQ(classifyColour({150, 149, 20}).confidence, 1);
  EXPECT_EQ(classifyColour({149, 150, 20}).colour, Colour::kGreen);
  const std::pair<Rgb8, Colour> secondaries[] = {{{150, 150, 20}, Colour::kGreen},
                                                 {{20, 150, 150}, Colour::kBlue},
                                                 {{150, 20, 150}, Colour::kRed}};
  for (const auto& [rgb, colour] : secondaries) {
    const ColourClass c = classifyColour(rgb);
    EXPECT_TRUE(c.present);
    EXPECT_EQ(c.colour, colour);
    EXPECT_EQ(c.confidence, 0);
  }
  EXPECT_EQ(classifyColour({150, 20, 151}).colour, Colour::kBlue);
}

TEST(DirectColourClassify, DarkAndUnsaturatedColoursAreNone) {
  const DirectColourParams params;  // minValue 24, minSaturationPermille 200
  EXPECT_FALSE(classifyColour({23, 0, 0}, params).present);
  EXPECT_TRUE(classifyColour({24, 0, 0}, params).present);
  EXPECT_FALSE(classifyColour({100, 100, 100}, params).present);
  EXPECT_FALSE(classifyColour({100, 90, 81}, params).present);  // saturation 190 ‰
  EXPECT_TRUE(classifyColour({100, 90, 80}, params).present);   // 200 ‰
  EXPECT_FALSE(classifyColour({0, 0, 0}, {0, 0}).present);      // black ties
  EXPECT_TRUE(classifyColour({2, 1, 1}, {0, 0}).present);
  EXPECT_TRUE(classifyColour({255, 1, 0}, {0, 1000}).present);  // saturation 1000 ‰
  EXPECT_FALSE(classifyColour({255, 1, 1}, {0, 1000}).present);
}

using test::stripeAt;
using test::superpose;
using test::SyntheticPattern;

struct Found {
  int boundaries = 0;  // detections
  int correct = 0;     // of those, at a stripe boundary (|error| < 0.5 px) with its transition
  double rmsPx = 0;
  int owners = 0;    // pixels within half a pixel of a stripe boundary, along the direction
  int recalled = 0;  // of those, with a detection in their 3 × 3 neighbourhood
};

double radians(double degrees) {
  return degrees * std::numbers::pi / 180.0;
}

// Every boundary in the inner area checked against `pattern`, read along directionDeg.
Found check(ConstBoundaryPlane plane, const SyntheticPattern& pattern, double directionDeg) {
  const int w = plane.width();
  const int h = plane.height();
  const double d = radians(directionDeg);
  // Stripe units per pixel along the reading direction (signed).
  const double along = std::cos(d - radians(pattern.angleDeg)) / pattern.stripePx;
  Found f;
  double sumSq = 0;
  for (int y = 4; y < h - 4; ++y) {
    for (int x = 4; x < w - 4; ++x) {
      const double sHere = stripeAt(pattern, w, h, x, y);
      const double deltaPx = (std::round(sHere) - sHere) / along;
      if (deltaPx >= -0.5 && deltaPx < 0.5) {
        ++f.owners;
        bool any = false;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            any = any || plane(x + dx, y + dy).present();
          }
        }
        f.recalled += any ? 1 : 0;
      }
      const Boundary b = plane(x, y);
      if (!b.present()) {
        continue;
      }
      ++f.boundaries;
      EXPECT_LE(std::abs(b.offset), 128);
      const double offsetPx = b.offset / 256.0;
      const double s =
          stripeAt(pattern, w, h, x + offsetPx * std::cos(d), y + offsetPx * std::sin(d));
      const int k = static_cast<int>(std::lround(s));
      const double errorPx = (s - k) / std::abs(along);
      sumSq += errorPx * errorPx;
      if (k < 1 || k >= stripe::kStripes) {
        continue;
      }
      auto truth = stripe::transitionBetween(stripe::kSequence[static_cast<std::size_t>(k - 1)],
                                             stripe::kSequence[static_cast<std::size_t>(k)]);
      if (along < 0) {
        truth = stripe::reversed(truth);
      }
      f.correct += (b.kind() == truth && std::abs(errorPx) < 0.5) ? 1 : 0;
    }
  }
  f.rmsPx = f.boundaries > 0 ? std::sqrt(sumSq / f.boundaries) : 0;
  return f;
}

std::size_t area(int w, int h) {
  return static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
}

std::vector<std::uint16_t> constantDirection(int w, int h, double degrees) {
  std::vector<std::uint16_t> plane(area(w, h), BinAngle::fromDegrees(degrees).raw);
  return plane;
}

// Given one clean pattern at several angles, when its boundaries are read along its encoding
// direction, then there is one per stripe per line, each at a stripe boundary with its class,
// and the frame touched the heap not once.
class DirectColourSingle : public ::testing::TestWithParam<SyntheticPattern> {};

TEST_P(DirectColourSingle, BoundariesAreWhereThePatternPutsThemWithoutHeapUse) {
  const SyntheticPattern pattern = GetParam();
  constexpr int kW = 97;  // odd sizes
  constexpr int kH = 61;
  const auto image = superpose({pattern}, kW, kH);
  const auto directions = constantDirection(kW, kH, pattern.angleDeg);
  std::vector<Boundary> out(area(kW, kH), Boundary{7, 3, 9});  // garbage: every pixel is written

  const test::AllocationCounter counter;
  const auto ok = directColourBoundaries(*ConstRgbView::packed(image, kW, kH),
                                         *ConstDirectionPlane::packed(directions, kW, kH),
                                         *BoundaryPlane::packed(out, kW, kH));
  EXPECT_EQ(counter.allocations(), 0U);
  ASSERT_TRUE(ok.has_value()) << ok.error().message;

  const auto plane = *ConstBoundaryPlane::packed(out, kW, kH);
  const Found f = check(plane, pattern, pattern.angleDeg);
  EXPECT_GT(f.owners, 500);
  EXPECT_EQ(f.recalled, f.owners);
  // No boundary is recorded twice. Axis-aligned, every pixel within half a pixel of a boundary
  // holds it; obliquely about a quarter do not (the bilinear sample a pixel ahead is blurred
  // more than the pixel itself, which moves the crossings read from either side away from the
  // pixel), though each has a detection next to it (above).
  EXPECT_LE(f.boundaries, f.owners);
  EXPECT_GE(f.boundaries, 0.7 * f.owners);
  EXPECT_GE(f.correct, 0.99 * f.boundaries);
  EXPECT_LT(f.rmsPx, 0.2);
  std::printf(
      "%.0f deg: %d detections, %d pixels within half a pixel of a boundary, position "
      "rms %.3f px\n",
      pattern.angleDeg, f.boundaries, f.owners, f.rmsPx);
  for (int x = 0; x < kW; ++x) {
    EXPECT_FALSE(plane(x, 0).present());
    EXPECT_FALSE(plane(x, kH - 1).present());
  }
  for (int y = 0; y < kH; ++y) {
    EXPECT_FALSE(plane(0, y).present());
    EXPECT_FALSE(plane(kW - 1, y).present());
  }
}

INSTANTIATE_TEST_SUITE_P(
    Angles, DirectColourSingle,
    ::testing::Values(SyntheticPattern{0, 4.0, 120}, SyntheticPattern{90, 4.0, 120},
                      SyntheticPattern{180, 4.0, 120}, SyntheticPattern{30, 4.5, 120},
                      SyntheticPattern{-45, 5.0, 120}, SyntheticPattern{100, 3.5, 120}));

// Given one pattern, when it is read against its encoding direction, then every boundary is
// found again with the reversed transition (the class is always read along +direction).
TEST(DirectColour, ReadingAgainstTheDirectionReversesEveryTransition) {
  constexpr int kW = 64;
  constexpr int kH = 32;
  const SyntheticPattern pattern{20, 4.0, 120};
  const auto image = superpose({pattern}, kW, kH);
  const auto view = *ConstRgbView::packed(image, kW, kH);
  const auto forward = constantDirection(kW, kH, 20);
  const auto backward = constantDirection(kW, kH, 200);
  std::vector<Boundary> a(area(kW, kH));
  std::vector<Boundary> b(area(kW, kH));
  ASSERT_TRUE(directColourBoundaries(view, *ConstDirectionPlane::packed(forward, kW, kH),
                                     *BoundaryPlane::packed(a, kW, kH))
                  .has_value());
  ASSERT_TRUE(directColourBoundaries(view, *ConstDirectionPlane::packed(backward, kW, kH),
                                     *BoundaryPlane::packed(b, kW, kH))
                  .has_value());
  const Found fa = check(*ConstBoundaryPlane::packed(a, kW, kH), pattern, 20);
  const Found fb = check(*ConstBoundaryPlane::packed(b, kW, kH), pattern, 200);
  EXPECT_GE(fa.recalled, 0.99 * fa.owners);
  EXPECT_GE(fb.recalled, 0.99 * fb.owners);
  EXPECT_GE(fa.correct, 0.99 * fa.boundaries);
  EXPECT_GE(fb.correct, 0.99 * fb.boundaries);
}

// Given two patterns 90° apart, the first brighter, when each projector's boundaries are read
// along its own direction, then the hue reads the brighter pattern everywhere: its boundaries
// are found, the dimmer one's are not (paper §2: the superposed colour does not say which
// projector's stripe is there).
TEST(DirectColour, SuperposedTheHueReadsOnlyTheBrighterPattern) {
  constexpr int kW = 96;
  constexpr int kH = 64;
  const SyntheticPattern bright{0, 4.0, 120};
  const SyntheticPattern dim{90, 4.0, 80};
  const auto image = superpose({bright, dim}, kW, kH);
  const auto view = *ConstRgbView::packed(image, kW, kH);
  std::vector<Boundary> out(area(kW, kH));
  const auto plane = *BoundaryPlane::packed(out, kW, kH);

  const auto alongBright = constantDirection(kW, kH, bright.angleDeg);
  ASSERT_TRUE(directColourBoundaries(view, *ConstDirectionPlane::packed(alongBright, kW, kH), plane)
                  .has_value());
  const Found fb = check(plane, bright, bright.angleDeg);
  EXPECT_GE(fb.recalled, 0.99 * fb.owners);
  EXPECT_GE(fb.correct, 0.95 * fb.boundaries);

  const auto alongDim = constantDirection(kW, kH, dim.angleDeg);
  ASSERT_TRUE(directColourBoundaries(view, *ConstDirectionPlane::packed(alongDim, kW, kH), plane)
                  .has_value());
  const Found fd = check(plane, dim, dim.angleDeg);
  EXPECT_LT(fd.correct, 0.05 * fd.owners);
  std::printf("bright: %d of %d boundaries correct; dim: %d detections, %d correct, of %d\n",
              fb.correct, fb.owners, fd.boundaries, fd.correct, fd.owners);
}

TEST(DirectColour, RejectsPlanesOfAnotherSizeAndParametersOutOfRange) {
  std::vector<Rgb8> pixels(area(8, 6));
  std::vector<std::uint16_t> directions(area(8, 6));
  std::vector<Boundary> out(area(8, 6));
  const auto image = *ConstRgbView::packed(pixels, 8, 6);
  const auto wrongDirection = directColourBoundaries(
      image, *ConstDirectionPlane::packed(directions, 6, 8), *BoundaryPlane::packed(out, 8, 6));
  ASSERT_FALSE(wrongDirection.has_value());
  EXPECT_EQ(wrongDirection.error().code, Errc::kSizeMismatch);
  const auto wrongOut =
      directColourBoundaries(image, *ConstDirectionPlane::packed(directions, 8, 6),
                             *BoundaryPlane::packed(std::span(out).first(area(8, 5)), 8, 5));
  ASSERT_FALSE(wrongOut.has_value());
  EXPECT_EQ(wrongOut.error().code, Errc::kSizeMismatch);
  for (const DirectColourParams bad : {DirectColourParams{-1, 200}, DirectColourParams{256, 200},
                                       DirectColourParams{24, -1}, DirectColourParams{24, 1001}}) {
    const auto r = directColourBoundaries(image, *ConstDirectionPlane::packed(directions, 8, 6),
                                          *BoundaryPlane::packed(out, 8, 6), bad);
    ASSERT_FALSE(r.has_value());
    EXPECT_EQ(r.error().code, Errc::kInvalidArgument);
  }
}

// Tiny and padded images: only border pixels, or rows with a stride larger than the row.
TEST(DirectColour, TinyAndStridedImagesHaveNoBoundaryOnTheBorder) {
  for (const auto& [w, h] : {std::pair{1, 1}, std::pair{2, 2}, std::pair{3, 1}, std::pair{0, 0}}) {
    std::vector<Rgb8> pixels(area(w, h), Rgb8{200, 0, 0});
    std::vector<std::uint16_t> directions(area(w, h), 0);
    std::vector<Boundary> out(area(w, h), Boundary{0, 1, 0});
    ASSERT_TRUE(directColourBoundaries(*ConstRgbView::packed(pixels, w, h),
                                       *ConstDirectionPlane::packed(directions, w, h),
                                       *BoundaryPlane::packed(out, w, h))
                    .has_value());
    for (const Boundary& b : out) {
      EXPECT_FALSE(b.present());
    }
  }
  // 3 × 3 image inside a 5-pixel stride: R | G | B columns, read along +x. The centre pixel
  // sees both boundaries exactly half a pixel away and keeps the one ahead (the one behind
  // belongs to the pixel before it: −½ is outside (−½, ½]).
  std::vector<Rgb8> padded(area(5, 3), Rgb8{0, 0, 0});
  for (int y = 0; y < 3; ++y) {
    padded[area(5, y)] = {200, 0, 0};
    padded[area(5, y) + 1] = {0, 200, 0};
    padded[area(5, y) + 2] = {0, 0, 200};
    padded[area(5, y) + 3] = {200, 0, 0};  // padding
  }
  std::vector<std::uint16_t> directions(area(3, 3), 0);
  std::vector<Boundary> out(area(3, 3));
  const auto image = *ConstRgbView::create(reinterpret_cast<const std::byte*>(padded.data()), 3, 3,
                                           5 * static_cast<std::ptrdiff_t>(sizeof(Rgb8)));
  ASSERT_TRUE(directColourBoundaries(image, *ConstDirectionPlane::packed(directions, 3, 3),
                                     *BoundaryPlane::packed(out, 3, 3))
                  .has_value());
  const Boundary centre = out[4];
  ASSERT_TRUE(centre.present());
  EXPECT_EQ(centre.offset, 128);
  EXPECT_EQ(centre.kind(), stripe::Transition::kPlusGB);
  EXPECT_EQ(centre.confidence, 255);
}

}  // namespace
}  // namespace smx::algo
