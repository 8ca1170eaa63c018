#include "smx/algo/pattern_image.hpp"

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "pattern_sampler.hpp"

namespace smx::algo {
namespace {

Projector makeProjector(double angleDeg, double stripePx, double offsetPx) {
  Projector p;
  p.id = "proj0";
  p.width = 1024;
  p.height = 768;
  p.pattern = {angleDeg, stripePx, offsetPx};
  return p;
}

std::vector<Rgb8> render(const Projector& p) {
  std::vector<Rgb8> pixels(static_cast<std::size_t>(p.width) * static_cast<std::size_t>(p.height));
  auto view = RgbView::packed(pixels, p.width, p.height);
  EXPECT_TRUE(view.has_value());
  EXPECT_TRUE(renderPatternImage(p, *view).has_value());
  return pixels;
}

// Given a pattern at any angle, when the image is sampled along the axis at the stripe centres,
// then the colours are the sequence in +axis order and each 7-stripe window decodes to its index.
TEST(PatternImage, SequenceRecoveredAlongAxisAtAnyAngle) {
  for (double angle = -180.0; angle < 360.0; angle += 13.0) {
    for (const double stripePx : {3.0, 8.5}) {
      const auto proj = makeProjector(angle, stripePx, angle / 10.0);
      const auto pixels = render(proj);
      const auto view = *ConstRgbView::packed(pixels, proj.width, proj.height);
      const auto sampled = test::sampleAlongAxis(view, proj.pattern);
      ASSERT_TRUE(sampled.has_value()) << "non-primary pixel at a stripe centre, angle " << angle;
      ASSERT_GE(sampled->size(), 7U) << "angle " << angle;
      for (const auto& s : *sampled) {
        ASSERT_EQ(s.colour, stripe::kSequence[static_cast<std::size_t>(s.index)])
            << "angle " << angle << " stripe " << s.index;
      }
      for (std::size_t k = 0; k + 7 <= sampled->size(); ++k) {
        if ((*sampled)[k + 6].index != (*sampled)[k].index + 6) {
          continue;  // not consecutive (cannot happen inside the image, but be exact)
        }
        std::array<stripe::Colour, 7> w{};
        for (std::size_t j = 0; j < 7; ++j) {
          w[j] = (*sampled)[k + j].colour;
        }
        EXPECT_EQ(stripe::decodeWindow(std::span<const stripe::Colour, 7>(w)), (*sampled)[k].index);
      }
    }
  }
}

// Given stripes narrow enough for the whole sequence to fit, the image shows all 198 stripes and
// black beyond both ends.
TEST(PatternImage, WholeSequenceVisibleAndBlackOutside) {
  const auto proj = makeProjector(0.0, 4.0, 0.0);
  const auto pixels = render(proj);
  const auto view = *ConstRgbView::packed(pixels, proj.width, proj.height);
  const auto sampled = test::sampleAlongAxis(view, proj.pattern);
  ASSERT_TRUE(sampled.has_value());
  EXPECT_EQ(sampled->size(), 198U);
  // Sequence spans 792 px centred on u = 511.5: [115.5, 907.5).
  EXPECT_EQ(view(100, 300), (Rgb8{0, 0, 0}));
  EXPECT_EQ(view(115, 300), (Rgb8{0, 0, 0}));
  EXPECT_NE(view(116, 300), (Rgb8{0, 0, 0}));
  EXPECT_NE(view(907, 300), (Rgb8{0, 0, 0}));
  EXPECT_EQ(view(908, 300), (Rgb8{0, 0, 0}));
  EXPECT_EQ(view(1023, 0), (Rgb8{0, 0, 0}));
}

TEST(PatternImage, StripeIndexGrowsAlongPositiveAxis) {
  // Axis pointing down (90°): stripe 0 at the top, stripe 197 at the bottom.
  const auto proj = makeProjector(90.0, 2.0, 0.0);
  EXPECT_LT(stripeCoordinate(proj.pattern, proj.width, proj.height, 500, 300),
            stripeCoordinate(proj.pattern, proj.width, proj.height, 500, 400));
  EXPECT_DOUBLE_EQ(stripeCoordinate(proj.pattern, proj.width, proj.height, 511.5, 383.5), 99.0);
  // An offset moves the sequence along +axis: the centre now shows the coordinate 10 px earlier.
  const auto shifted = makeProjector(90.0, 2.0, 10.0);
  EXPECT_DOUBLE_EQ(stripeCoordinate(shifted.pattern, proj.width, proj.height, 511.5, 383.5), 94.0);
}

TEST(PatternImage, RejectsWrongSizeAndNonPositiveStripe) {
  auto proj = makeProjector(0.0, 5.0, 0.0);
  std::vector<Rgb8> small(10 * 10);
  auto view = *RgbView::packed(small, 10, 10);
  const auto wrongSize = renderPatternImage(proj, view);
  ASSERT_FALSE(wrongSize.has_value());
  EXPECT_EQ(wrongSize.error().code, Errc::kSizeMismatch);
  proj.width = proj.height = 10;
  proj.pattern.stripePx = 0.0;
  const auto zero = renderPatternImage(proj, view);
  ASSERT_FALSE(zero.has_value());
  EXPECT_EQ(zero.error().code, Errc::kInvalidArgument);
}

}  // namespace
}  // namespace smx::algo
