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
  for (int p = 0; p < layout.projectors; ++p) {
    const std::span<const TileDirection> mine =
        tiles.subspan(static_cast<std::size_t>(p) * tileCount, tileCount);
    const auto angleAt = [&](int tx, int ty) {
      return mine[static_cast<std::size_t>(ty) * static_cast<std::size_t>(tilesX) +
                  static_cast<std::size_t>(tx)]
          .angle;
    };
    for (int y = 0; y < layout.height; ++y) {
      const TileInterp& ry = rows[static_cast<std::size_t>(y)];
      const std::int64_t wy = ry.weight;
      std::uint16_t* dst = out[static_cast<std::size_t>(p)].rowPtr(y);
      for (int x = 0; x < layout.width; ++x) {
        const TileInterp& cx = columns[static_cast<std::size_t>(x)];
        const std::uint16_t a00 = angleAt(cx.lower, ry.lower);
        const std::int64_t d10 = wrapDiff(angleAt(cx.upper, ry.lower), a00);
        const std::int64_t d01 = wrapDiff(angleAt(cx.lower, ry.upper), a00);
        const std::int64_t d11 = wrapDiff(angleAt(cx.upper, ry.upper), a00);
        const std::int64_t wx = cx.weight;
        const std::int64_t delta =
            (d10 * wx * (256 - wy) + d01 * (256 - wx) * wy + d11 * wx * wy + 32768) >> 16;
        dst[x] = static_cast<std::uint16_t>(a00 + static_cast<std::uint16_t>(delta));
      }
    }
  }
}

}  // namespace smx::algo::demux
