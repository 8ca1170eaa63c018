// Direction planes: each projector's tile angles interpolated bilinearly between tile centres,
// as wrapped differences from the lower-left tile's angle (int64), per pixel.
#include <cstdint>

#include "demux_kernels.hpp"

namespace smx::algo::demux {

void tileInterpolation(int pixels, int tilePx, int tiles, std::span<TileInterp> out) {
  const int span2 = 2 * tilePx;
  for (int x = 0; x < pixels; ++x) {
    const int u2 = 2 * x - (tilePx - 1);  // twice the distance from tile 0's centre
    TileInterp ti{};
    if (u2 <= 0) {
      ti = {0, 0, 0, 0};
    } else {
      const int lower = u2 / span2;
      if (lower >= tiles - 1) {
        ti.lower = ti.upper = static_cast<std::int16_t>(tiles - 1);
        ti.weight = 0;
      } else {
        ti.lower = static_cast<std::int16_t>(lower);
        ti.upper = static_cast<std::int16_t>(lower + 1);
        ti.weight = static_cast<std::int16_t>(((u2 - lower * span2) * 256) / span2);
      }
    }
    ti.nearest = static_cast<std::int16_t>(x / tilePx < tiles ? x / tilePx : tiles - 1);
    out[static_cast<std::size_t>(x)] = ti;
  }
}

void interpolateDirections(const DemuxLayout& layout, std::span<const TileDirection> tiles,
                           std::span<const TileInterp> columns, std::span<const TileInterp> rows,
                           std::span<const DirectionPlane> out) {
  const int tilesX = layout.tilesX();
  const std::size_t tileCount = layout.tileCount();
  const int w = layout.width;
  for (int p = 0; p < layout.projectors; ++p) {
    const TileDirection* mine = tiles.data() + static_cast<std::size_t>(p) * tileCount;
    for (int y = 0; y < layout.height; ++y) {
      const TileInterp& ry = rows[static_cast<std::size_t>(y)];
      const std::int32_t wy = ry.weight;
      const TileDirection* lowerRow =
          mine + static_cast<std::size_t>(ry.lower) * static_cast<std::size_t>(tilesX);
      const TileDirection* upperRow =
          mine + static_cast<std::size_t>(ry.upper) * static_cast<std::size_t>(tilesX);
      std::uint16_t* dst = out[static_cast<std::size_t>(p)].rowPtr(y);
      // Between two tile centres the four corners are fixed, and the bilinear sum
      //   d10·wx·(256 − wy) + d01·(256 − wx)·wy + d11·wx·wy + 2^15 = wx·slope + 256·base
      // is one multiply-add per pixel. Where the weight is 0 (outside the outer tile centres)
      // the upper column does not count, so the corners change only with the lower column.
      int lower = -1;
      std::uint16_t a00 = 0;
      std::int32_t slope = 0;
      std::int32_t base = 0;
      for (int x = 0; x < w; ++x) {
        const TileInterp& cx = columns[static_cast<std::size_t>(x)];
        if (cx.lower != lower) {
          lower = cx.lower;
          const auto l = static_cast<std::size_t>(lower);
          const auto u = static_cast<std::size_t>(lower + 1 < tilesX ? lower + 1 : lower);
          a00 = lowerRow[l].angle;
          const std::int32_t d10 = wrapDiff(lowerRow[u].angle, a00);
          const std::int32_t d01 = wrapDiff(upperRow[l].angle, a00);
          const std::int32_t d11 = wrapDiff(upperRow[u].angle, a00);
          slope = d10 * (256 - wy) + (d11 - d01) * wy;  // |slope| < 2^25
          base = d01 * wy + 128;                        // |base| < 2^23
        }
        // wx·slope + 256·base overflows int32; in int64 it is one scalar multiply-add.
        const std::int64_t sum = std::int64_t{cx.weight} * slope + std::int64_t{base} * 256;
        const auto delta = static_cast<std::int32_t>(sum >> 16);
        dst[x] = static_cast<std::uint16_t>(a00 + static_cast<std::uint16_t>(delta));
      }
    }
  }
}

}  // namespace smx::algo::demux
