// Reference of stage 3a (demux_reference.hpp): the bilinear sum per pixel, in int64.
// Schedule: schedule/interpolate.cpp (per band of rows between two tile rows' centres the terms
// that do not change with the row, split so that every product fits int32).
#include <cstdint>

#include "demux_reference.hpp"

namespace smx::algo::demux::reference {

namespace {

// Along one axis: the tile whose centre is at or before pixel v (clamped to the first and last
// centre) and the next one's weight in 1/256, from 2v − (T − 1), twice the distance from tile
// 0's centre.
struct Between {
  int lower;
  int upper;
  std::int64_t weight;
};

Between between(int v, int tilePx, int tiles) {
  const int u2 = 2 * v - (tilePx - 1);
  const int span2 = 2 * tilePx;
  if (u2 <= 0) {
    return {0, 0, 0};
  }
  const int lower = u2 / span2;
  if (lower >= tiles - 1) {
    return {tiles - 1, tiles - 1, 0};
  }
  return {lower, lower + 1, ((u2 - lower * span2) * 256) / span2};
}

}  // namespace

void interpolation(const DemuxLayout& layout, std::span<const TileDirection> tiles,
                   std::span<const DirectionPlane> out) {
  const int t = layout.params.tilePx;
  const auto tilesX = static_cast<std::size_t>(layout.tilesX());
  const std::size_t tileCount = layout.tileCount();
  for (int p = 0; p < layout.projectors; ++p) {
    const std::span<const TileDirection> mine =
        tiles.subspan(static_cast<std::size_t>(p) * tileCount, tileCount);
    const auto angle = [&](int i, int j) {
      return mine[static_cast<std::size_t>(j) * tilesX + static_cast<std::size_t>(i)].angle;
    };
    for (int y = 0; y < layout.height; ++y) {
      const Between row = between(y, t, layout.tilesY());
      for (int x = 0; x < layout.width; ++x) {
        const Between col = between(x, t, layout.tilesX());
        const std::uint16_t a00 = angle(col.lower, row.lower);
        const std::int64_t d10 = wrapDiff(angle(col.upper, row.lower), a00);
        const std::int64_t d01 = wrapDiff(angle(col.lower, row.upper), a00);
        const std::int64_t d11 = wrapDiff(angle(col.upper, row.upper), a00);
        const std::int64_t wx = col.weight;
        const std::int64_t wy = row.weight;
        const std::int64_t sum =
            d10 * wx * (256 - wy) + d01 * (256 - wx) * wy + d11 * wx * wy + 32768;
        out[static_cast<std::size_t>(p)](x, y) =
            static_cast<std::uint16_t>(a00 + static_cast<std::int32_t>(sum >> 16));
      }
    }
  }
}

}  // namespace smx::algo::demux::reference
