// Orientation demultiplexing on clean synthetic superpositions (host and aarch64): the layout
// and its memory, input checks, a frame without heap use, and boundaries where the analytic
// patterns put them. Accuracy on rendered scenes: demux_accuracy_test.cpp.
#include "smx/algo/demux.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "smx/algo/fixed_math.hpp"
#include "smx/algo/stripe_code.hpp"
#include "synthetic_stripes.hpp"

namespace smx::algo {
namespace {

constexpr std::size_t kMiB = std::size_t{1} << 20;

using test::stripeAt;
using test::superpose;
using test::SyntheticPattern;

// Predicted angles: the exact encoding directions, the same in every tile.
std::vector<std::uint16_t> exactPrediction(const DemuxLayout& layout,
                                           const std::vector<SyntheticPattern>& patterns) {
  std::vector<std::uint16_t> out;
  for (std::size_t t = 0; t < layout.tileCount(); ++t) {
    for (const auto& p : patterns) {
      out.push_back(BinAngle::fromDegrees(p.angleDeg).raw);
    }
  }
  return out;
}

TEST(Demux, WorkspaceFor640x480FitsTheBudgetAndCreateUsesNoMore) {
  for (const int projectors : {1, 2, 3}) {
    const DemuxLayout layout{640, 480, projectors, {}};
    const auto bytes = Demultiplexer::workspaceBytes(layout);
    ASSERT_TRUE(bytes.has_value());
    EXPECT_LE(*bytes, 16 * kMiB) << projectors << " projectors";
    std::vector<std::byte> memory(*bytes);
    Arena arena(memory);
    const std::vector<std::uint16_t> predicted(
        layout.tileCount() * static_cast<std::size_t>(projectors), 0);
    auto demux = Demultiplexer::create(layout, predicted, arena);
    ASSERT_TRUE(demux.has_value()) << demux.error().message;
    EXPECT_LE(arena.highWater(), *bytes);
    // One byte less than the report must still be enough, or the report is tight: either way the
    // report is within alignment slack of what create() used.
    EXPECT_GE(*bytes, arena.highWater());
    EXPECT_LT(*bytes - arena.highWater(), 1024U);
    ::testing::Test::RecordProperty("workspace_bytes_" + std::to_string(projectors),
                                    std::to_string(*bytes));
    std::printf("demux workspace 640x480, %d projector(s): %zu bytes (%.2f MiB)\n", projectors,
                *bytes, static_cast<double>(*bytes) / static_cast<double>(kMiB));
  }
}

TEST(Demux, CreateRejectsBadLayoutsAndATooSmallArena) {
  std::vector<std::byte> memory(1024);
  Arena arena(memory);
  const std::vector<std::uint16_t> none;
  EXPECT_FALSE(Demultiplexer::create({4, 480, 2, {}}, none, arena).has_value());
  EXPECT_FALSE(Demultiplexer::create({640, 480, 4, {}}, none, arena).has_value());
  DemuxParams even;
  even.windowTiles = 2;
  EXPECT_FALSE(Demultiplexer::workspaceBytes({640, 480, 2, even}).has_value());
  const DemuxLayout layout{64, 48, 2, {}};
  const std::vector<std::uint16_t> wrongCount(3, 0);
  const auto wrong = Demultiplexer::create(layout, wrongCount, arena);
  ASSERT_FALSE(wrong.has_value());
  EXPECT_EQ(wrong.error().code, Errc::kSizeMismatch);
  const std::vector<std::uint16_t> predicted(layout.tileCount() * 2, 0);
  const auto small = Demultiplexer::create(layout, predicted, arena);
  ASSERT_FALSE(small.has_value());
  EXPECT_EQ(small.error().code, Errc::kOutOfMemory);
  EXPECT_EQ(arena.used(), 0U);  // a failed create() gives its memory back
}

TEST(Demux, RunRejectsAnImageOfAnotherSize) {
  const DemuxLayout layout{64, 48, 2, {}};
  std::vector<std::byte> memory(*Demultiplexer::workspaceBytes(layout));
  Arena arena(memory);
  const std::vector<std::uint16_t> predicted(layout.tileCount() * 2, 0);
  auto demux = Demultiplexer::create(layout, predicted, arena);
  ASSERT_TRUE(demux.has_value());
  std::vector<Rgb8> pixels(64 * 47);
  const auto ok = demux->run(*ConstRgbView::packed(pixels, 64, 47));
  ASSERT_FALSE(ok.has_value());
  EXPECT_EQ(ok.error().code, Errc::kSizeMismatch);
}

// Given tile directions fixed from outside (stripemux eval's true-directions baseline), when a
// frame runs, then the direction stage keeps them instead of estimating its own (which would
// find both patterns at their true angles), without heap use; a wrong count is refused.
TEST(Demux, FixedTileDirectionsReplaceTheEstimate) {
  const std::vector<SyntheticPattern> patterns{{0.0, 6.0}, {90.0, 6.0}};
  constexpr int kW = 96;
  constexpr int kH = 64;
  const auto image = superpose(patterns, kW, kH);
  const DemuxLayout layout{kW, kH, 2, {}};
  std::vector<std::byte> memory(*Demultiplexer::workspaceBytes(layout));
  Arena arena(memory);
  auto demux = Demultiplexer::create(layout, exactPrediction(layout, patterns), arena);
  ASSERT_TRUE(demux.has_value());
  const std::vector<TileDirection> tooFew(layout.tileCount(), TileDirection{});
  EXPECT_EQ(demux->fixTileDirections(tooFew).error().code, Errc::kSizeMismatch);

  // Projector 0 absent everywhere, projector 1 present at 45°: not what the image holds.
  std::vector<TileDirection> fixed(layout.tileCount() * 2, TileDirection{});
  for (std::size_t t = 0; t < layout.tileCount(); ++t) {
    fixed[layout.tileCount() + t] = {BinAngle::fromDegrees(45.0).raw, 1};
  }
  ASSERT_TRUE(demux->fixTileDirections(fixed).has_value());
  const test::AllocationCounter counter;
  ASSERT_TRUE(demux->run(*ConstRgbView::packed(image, kW, kH)).has_value());
  EXPECT_EQ(counter.allocations(), 0U);
  for (std::size_t t = 0; t < layout.tileCount(); ++t) {
    EXPECT_EQ(demux->tileDirections(0)[t].present, 0) << "tile " << t;
    EXPECT_EQ(demux->tileDirections(1)[t].present, 1) << "tile " << t;
    EXPECT_EQ(demux->tileDirections(1)[t].angle, BinAngle::fromDegrees(45.0).raw) << "tile " << t;
  }
}

// The angle from a to b in degrees, of axes (mod 180°), in [-90, 90).
double axisDiffDeg(std::uint16_t a, std::uint16_t b) {
  return std::fmod((b - a) * 360.0 / 65536.0 + 450.0, 180.0) - 90.0;
}

// Given one clean pattern at 0° and a prediction that errs by a ramp, 0° over the right half up to
// 60° at the left edge (as a surface turned far from the nominal one errs), when a frame runs,
// then the lobe is found in every tile, also where it lies beyond the 30° tolerance of the
// prediction: the found tiles grow into them. (One pattern: the crossings of two clean ones make
// diagonal lobes of their own, which a prediction 45° off would match first.)
TEST(Demux, FoundDirectionsGrowBeyondTheToleranceOfThePrediction) {
  const std::vector<SyntheticPattern> patterns{{0.0, 5.0}};
  constexpr int kW = 160;
  constexpr int kH = 64;
  const auto image = superpose(patterns, kW, kH);
  const DemuxLayout layout{kW, kH, 1, {}};
  auto predicted = exactPrediction(layout, patterns);
  const int tilesX = layout.tilesX();
  for (std::size_t t = 0; t < layout.tileCount(); ++t) {
    const int tx = static_cast<int>(t) % tilesX;
    const double errDeg = tx < tilesX / 2 ? 60.0 * (tilesX / 2 - tx) / (tilesX / 2) : 0.0;
    predicted[t] = BinAngle::fromDegrees(errDeg).raw;
  }
  std::vector<std::byte> memory(*Demultiplexer::workspaceBytes(layout));
  Arena arena(memory);
  auto demux = Demultiplexer::create(layout, predicted, arena);
  ASSERT_TRUE(demux.has_value());
  ASSERT_TRUE(demux->run(*ConstRgbView::packed(image, kW, kH)).has_value());
  const std::uint16_t truth = BinAngle::fromDegrees(0.0).raw;
  for (std::size_t t = 0; t < layout.tileCount(); ++t) {
    if (static_cast<int>(t) % tilesX == 0) {
      continue;  // the edge column's median of offsets sees only the ramp's steeper side
    }
    const TileDirection d = demux->tileDirections(0)[t];
    EXPECT_EQ(d.present, 1) << "tile " << t;
    EXPECT_LT(std::abs(axisDiffDeg(d.angle, truth)), 2.0) << "tile " << t;
  }
}

// Given projector 0's stripes at 0° left of x = 78 and at 28° right of it (two surfaces meeting
// at an edge, both within the tolerance of the prediction, 0°), projector 1's at 90°, when a
// frame runs, then the first tile column right of the edge takes the 28° lobe that the tile
// itself holds, though the 0° lobe, a third of its window, is the nearer the prediction.
TEST(Demux, ATileTakesTheLobeOfItsOwnSurfaceAtAnEdge) {
  constexpr int kW = 160;
  constexpr int kH = 64;
  constexpr int kEdge = 78;  // the first tile right of it has no sample whose support crosses it
  const auto left = superpose({{0.0, 5.0}, {90.0, 5.0}}, kW, kH);
  const auto right = superpose({{28.0, 5.0}, {90.0, 5.0}}, kW, kH);
  std::vector<Rgb8> image = left;
  for (int y = 0; y < kH; ++y) {
    for (int x = kEdge; x < kW; ++x) {
      const auto i = static_cast<std::size_t>(y) * kW + static_cast<std::size_t>(x);
      image[i] = right[i];
    }
  }
  const DemuxLayout layout{kW, kH, 2, {}};
  std::vector<std::byte> memory(*Demultiplexer::workspaceBytes(layout));
  Arena arena(memory);
  auto demux =
      Demultiplexer::create(layout, exactPrediction(layout, {{0.0, 5.0}, {90.0, 5.0}}), arena);
  ASSERT_TRUE(demux.has_value());
  ASSERT_TRUE(demux->run(*ConstRgbView::packed(image, kW, kH)).has_value());
  const int tilesX = layout.tilesX();
  const int edgeTile = kEdge / layout.params.tilePx + 1;
  for (int ty = 1; ty + 1 < layout.tilesY(); ++ty) {
    const auto t = static_cast<std::size_t>(ty * tilesX + edgeTile);
    const TileDirection d = demux->tileDirections(0)[t];
    EXPECT_EQ(d.present, 1) << "tile row " << ty;
    EXPECT_LT(std::abs(axisDiffDeg(d.angle, BinAngle::fromDegrees(28.0).raw)), 3.0)
        << "tile row " << ty;
    const TileDirection before = demux->tileDirections(0)[t - 1];
    EXPECT_LT(std::abs(axisDiffDeg(before.angle, BinAngle::fromDegrees(0.0).raw)), 3.0)
        << "tile row " << ty;
  }
}

// Projector p's boundaries in the frame's inner area against its pattern: how many, how many
// of the right class within ½ px, and the position error's RMS along the encoding direction.
struct PatternScore {
  int found = 0;
  int correct = 0;
  double rmsPx = 0;
};

PatternScore scorePattern(const Demultiplexer& demux, int p, const SyntheticPattern& pattern, int w,
                          int h) {
  const double a = pattern.angleDeg * std::numbers::pi / 180.0;
  PatternScore score;
  double sumSq = 0;
  for (int y = 8; y < h - 8; ++y) {
    for (int x = 8; x < w - 8; ++x) {
      const Boundary b = demux.boundaries(p)(x, y);
      if (!b.present()) {
        continue;
      }
      ++score.found;
      const double along = b.offset / 256.0;
      const double s = stripeAt(pattern, w, h, x + along * std::cos(a), y + along * std::sin(a));
      const int k = static_cast<int>(std::lround(s));
      const double errorPx = (s - k) * pattern.stripePx;
      sumSq += errorPx * errorPx;
      const auto truth =
          stripe::transitionBetween(stripe::kSequence[static_cast<std::size_t>(k - 1)],
                                    stripe::kSequence[static_cast<std::size_t>(k)]);
      score.correct += (b.kind() == truth && std::abs(errorPx) < 0.5) ? 1 : 0;
    }
  }
  score.rmsPx = score.found > 0 ? std::sqrt(sumSq / score.found) : 0;
  return score;
}

// Given two clean patterns 90° apart (and, separately, 70° apart), when a frame runs, then each
// projector's boundaries lie where its stripe coordinate crosses an integer, with the class of
// the colours on either side, and the frame touched the heap not once.
class DemuxSynthetic : public ::testing::TestWithParam<std::vector<SyntheticPattern>> {};

TEST_P(DemuxSynthetic, BoundariesAreWhereThePatternsPutThemWithoutHeapUse) {
  const auto& patterns = GetParam();
  constexpr int kW = 160;
  constexpr int kH = 120;
  const auto image = superpose(patterns, kW, kH);
  const DemuxLayout layout{kW, kH, static_cast<int>(patterns.size()), {}};
  std::vector<std::byte> memory(*Demultiplexer::workspaceBytes(layout));
  Arena arena(memory);
  auto demux = Demultiplexer::create(layout, exactPrediction(layout, patterns), arena);
  ASSERT_TRUE(demux.has_value());
  const auto view = *ConstRgbView::packed(image, kW, kH);

  const test::AllocationCounter counter;
  for (int frame = 0; frame < 3; ++frame) {
    ASSERT_TRUE(demux->run(view).has_value());
  }
  EXPECT_EQ(counter.allocations(), 0U);

  for (std::size_t p = 0; p < patterns.size(); ++p) {
    const PatternScore score = scorePattern(*demux, static_cast<int>(p), patterns[p], kW, kH);
    // Boundaries cross every row or column of the inner area about once per stripe width.
    const double expected = (kW - 16) * (kH - 16) / patterns[p].stripePx;
    EXPECT_GT(score.found, 0.9 * expected) << "projector " << p;
    EXPECT_LT(score.found, 1.1 * expected) << "projector " << p;
    EXPECT_GE(score.correct, 0.99 * score.found) << "projector " << p;
    EXPECT_LT(score.rmsPx, 0.15) << "projector " << p;
  }
}

INSTANTIATE_TEST_SUITE_P(Patterns, DemuxSynthetic,
                         ::testing::Values(std::vector<SyntheticPattern>{{0, 4.0}, {90, 4.0}},
                                           std::vector<SyntheticPattern>{{10, 4.5}, {80, 4.5}},
                                           std::vector<SyntheticPattern>{{0, 4.0}, {70, 4.0}}));

// Given two clean patterns 90° apart on a surface whose colour changes across projector 0's
// stripes (each channel's reflectance a sinusoid of its own phase, 0.5 to 1 over 64 px), when a
// frame runs, then projector 0's boundaries stay within 0.04 px RMS: the local colour divides
// the response, but neither its steps between tiles nor its slope moves a maximum. (When the
// position came from the divided strengths, tile by tile: 0.059 px here, 0.040 on white.)
TEST(Demux, SurfaceColourChangesDoNotMoveTheBoundaries) {
  constexpr int kW = 160;
  constexpr int kH = 120;
  const std::vector<SyntheticPattern> patterns{{0, 5.0}, {90, 5.0}};
  auto image = superpose(patterns, kW, kH);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      Rgb8& px = image[static_cast<std::size_t>(y) * kW + static_cast<std::size_t>(x)];
      const auto reflect = [x](std::uint8_t v, double phase) {
        const double r = 0.75 + 0.25 * std::sin(2 * std::numbers::pi * x / 64.0 + phase);
        return static_cast<std::uint8_t>(std::lround(v * r));
      };
      px = {reflect(px.r, 0.0), reflect(px.g, 2.1), reflect(px.b, 4.2)};
    }
  }
  const DemuxLayout layout{kW, kH, 2, {}};
  std::vector<std::byte> memory(*Demultiplexer::workspaceBytes(layout));
  Arena arena(memory);
  auto demux = Demultiplexer::create(layout, exactPrediction(layout, patterns), arena);
  ASSERT_TRUE(demux.has_value());
  ASSERT_TRUE(demux->run(*ConstRgbView::packed(image, kW, kH)).has_value());
  const PatternScore score = scorePattern(*demux, 0, patterns[0], kW, kH);
  std::printf("coloured surface: %d boundaries, %d right, position RMS %.3f px\n", score.found,
              score.correct, score.rmsPx);
  const double expected = (kW - 16) * (kH - 16) / patterns[0].stripePx;
  EXPECT_GT(score.found, 0.9 * expected);
  EXPECT_GE(score.correct, 0.99 * score.found);
  EXPECT_LT(score.rmsPx, 0.04);
}

}  // namespace
}  // namespace smx::algo
