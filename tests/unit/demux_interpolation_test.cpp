// The per-pixel encoding directions of orientation demultiplexing: each projector's tile angles
// interpolated bilinearly between tile centres, checked against the interpolation written out
// in double from the tile geometry (tile i's centre at i·T + (T − 1)/2, edge tiles held beyond
// the outer centres), on tile fields that wrap through 0°.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "smx/algo/arena.hpp"
#include "smx/algo/demux.hpp"

namespace smx::algo {
namespace {

double wrappedDiff(double a, double b) {
  return std::remainder(a - b, 65536.0);
}

// Where pixel p falls between tile centres: the lower tile and the upper one's weight.
struct Between {
  int lower;
  double weight;
};
Between between(int p, int tilePx, int tiles) {
  const double centre0 = (tilePx - 1) / 2.0;
  const double u = (p - centre0) / tilePx;
  if (u <= 0) {
    return {0, 0.0};
  }
  if (u >= tiles - 1) {
    return {tiles - 1, 0.0};
  }
  const int lower = static_cast<int>(std::floor(u));
  return {lower, u - lower};
}

// Given random tile angles (per projector a field around its own base, one crossing 0°) fixed
// into the demultiplexer, when a frame runs, then every pixel's direction is the bilinear
// interpolation of the four surrounding tile centres' angles within one raw unit (1/65536 turn).
TEST(DemuxInterpolation, DirectionsAreBilinearBetweenTileCentres) {
  constexpr int kW = 101;  // not whole tiles: the edge tiles are partial
  constexpr int kH = 59;
  const DemuxLayout layout{kW, kH, 2, {}};
  const int tilesX = layout.tilesX();
  const int tilesY = layout.tilesY();
  const int tilePx = layout.params.tilePx;
  std::vector<std::byte> memory(*Demultiplexer::workspaceBytes(layout));
  Arena arena(memory);
  const std::vector<std::uint16_t> predicted(layout.tileCount() * 2, 0);
  auto demux = Demultiplexer::create(layout, predicted, arena);
  ASSERT_TRUE(demux.has_value());

  std::mt19937 rng(7);
  std::uniform_int_distribution<int> spread(-6000, 6000);  // ±33°: neighbours never wrap apart
  const int bases[2] = {65000, 20000};                     // projector 0 crosses 0°
  std::vector<TileDirection> tiles(layout.tileCount() * 2);
  for (std::size_t p = 0; p < 2; ++p) {
    for (std::size_t t = 0; t < layout.tileCount(); ++t) {
      tiles[p * layout.tileCount() + t] = {
          static_cast<std::uint16_t>((bases[p] + spread(rng)) & 0xFFFF), 1};
    }
  }
  ASSERT_TRUE(demux->fixTileDirections(tiles).has_value());
  const std::vector<Rgb8> image(static_cast<std::size_t>(kW) * kH, Rgb8{});
  ASSERT_TRUE(demux->run(*ConstRgbView::packed(image, kW, kH)).has_value());

  for (int p = 0; p < 2; ++p) {
    const auto angle = [&](int tx, int ty) {
      return static_cast<double>(
          tiles[static_cast<std::size_t>(p) * layout.tileCount() +
                static_cast<std::size_t>(ty) * static_cast<std::size_t>(tilesX) +
                static_cast<std::size_t>(tx)]
              .angle);
    };
    int worst = 0;
    for (int y = 0; y < kH; ++y) {
      const Between by = between(y, tilePx, tilesY);
      const int y1 = by.lower + 1 < tilesY ? by.lower + 1 : by.lower;
      for (int x = 0; x < kW; ++x) {
        const Between bx = between(x, tilePx, tilesX);
        const int x1 = bx.lower + 1 < tilesX ? bx.lower + 1 : bx.lower;
        const double a00 = angle(bx.lower, by.lower);
        const double expected =
            a00 + bx.weight * (1 - by.weight) * wrappedDiff(angle(x1, by.lower), a00) +
            (1 - bx.weight) * by.weight * wrappedDiff(angle(bx.lower, y1), a00) +
            bx.weight * by.weight * wrappedDiff(angle(x1, y1), a00);
        const double got = demux->directions(p).rowPtr(y)[x];
        const double error = std::abs(wrappedDiff(got, expected));
        EXPECT_LE(error, 1.0) << "projector " << p << " at (" << x << ", " << y << ")";
        worst = std::max(worst, static_cast<int>(std::ceil(error)));
      }
    }
    std::printf("projector %d: worst direction error %d raw units\n", p, worst);
  }
}

}  // namespace
}  // namespace smx::algo
