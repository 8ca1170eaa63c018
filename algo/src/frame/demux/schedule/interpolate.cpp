// Direction planes, the schedule of interpolateDirections() (reference:
// reference/interpolate.cpp): each projector's tile angles interpolated bilinearly between tile
// centres, as wrapped differences from the lower-left tile's angle, per pixel.
#include <algorithm>
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

namespace {

// A band of rows shares its lower and upper tile rows, so per pixel the bilinear sum
//   d10·wx·(256 − wy) + (d01·(256 − wx) + d11·wx)·wy + 2^15 = 256·P + wy·(Q − P) + 2^15
// with P = d10·wx and Q = d01·(256 − wx) + d11·wx (the d's wrapped differences from the
// lower-left tile's angle a00) changes only with wy. wy·(Q − P) overflows int32; with
// Q − P = 256·h + l, 0 <= l < 256, the sum >> 16 is (P + wy·h + ((wy·l + 2^15) >> 8)) >> 8
// exactly (floor division nests), every term within int32.
enum BandRow : std::size_t { kA00, kP, kH, kL };

void bandLines(const TileDirection* lowerRow, const TileDirection* upperRow, int tilesX,
               std::span<const TileInterp> columns, const RowBlock<std::int32_t>& band) {
  std::int32_t* a00 = band.row(kA00);
  std::int32_t* p = band.row(kP);
  std::int32_t* h = band.row(kH);
  std::int32_t* l = band.row(kL);
  for (std::size_t x = 0; x < columns.size(); ++x) {
    const TileInterp& cx = columns[x];
    const auto lo = static_cast<std::size_t>(cx.lower);
    // Where the weight is 0 (outside the outer tile centres) the upper column does not count.
    const auto up = static_cast<std::size_t>(cx.lower + 1 < tilesX ? cx.lower + 1 : cx.lower);
    const std::uint16_t corner = lowerRow[lo].angle;
    const std::int32_t d10 = wrapDiff(lowerRow[up].angle, corner);
    const std::int32_t d01 = wrapDiff(upperRow[lo].angle, corner);
    const std::int32_t d11 = wrapDiff(upperRow[up].angle, corner);
    const std::int32_t wx = cx.weight;
    const std::int32_t lowerLine = d10 * wx;                     // |P| < 2^23
    const std::int32_t upperLine = d01 * (256 - wx) + d11 * wx;  // |Q| < 2^23
    const std::int32_t diff = upperLine - lowerLine;
    a00[x] = corner;
    p[x] = lowerLine;
    h[x] = diff >> 8;
    l[x] = diff & 255;
  }
}

}  // namespace

void interpolateDirections(const DemuxLayout& layout, std::span<const TileDirection> tiles,
                           std::span<const TileInterp> columns, std::span<const TileInterp> rows,
                           const RowBlock<std::int32_t>& band, std::span<const DirectionPlane> out,
                           RowRange outRows) {
  const int tilesX = layout.tilesX();
  const int yBegin = std::max(outRows.begin, 0);
  const int yEnd = std::min(outRows.end, layout.height);
  const std::size_t tileCount = layout.tileCount();
  const int w = layout.width;
  const std::int32_t* a00 = band.row(kA00);
  const std::int32_t* p = band.row(kP);
  const std::int32_t* h = band.row(kH);
  const std::int32_t* l = band.row(kL);
  for (int q = 0; q < layout.projectors; ++q) {
    const TileDirection* mine = tiles.data() + static_cast<std::size_t>(q) * tileCount;
    int lower = -1;
    int upper = -1;
    for (int y = yBegin; y < yEnd; ++y) {
      const TileInterp& ry = rows[static_cast<std::size_t>(y)];
      if (ry.lower != lower || ry.upper != upper) {
        lower = ry.lower;
        upper = ry.upper;
        bandLines(mine + static_cast<std::size_t>(lower) * static_cast<std::size_t>(tilesX),
                  mine + static_cast<std::size_t>(upper) * static_cast<std::size_t>(tilesX), tilesX,
                  columns, band);
      }
      const std::int32_t wy = ry.weight;
      std::uint16_t* dst = out[static_cast<std::size_t>(q)].rowPtr(y);
      for (int x = 0; x < w; ++x) {
        const std::int32_t delta = (p[x] + wy * h[x] + ((wy * l[x] + 32768) >> 8)) >> 8;
        dst[x] = static_cast<std::uint16_t>(a00[x] + delta);
      }
    }
  }
}

#if SMX_DEMUX_AVX2
SMX_AVX2_TWIN void avx2::interpolateDirections(
    const DemuxLayout& layout, std::span<const TileDirection> tiles,
    std::span<const TileInterp> columns, std::span<const TileInterp> rows,
    const RowBlock<std::int32_t>& band, std::span<const DirectionPlane> out, RowRange outRows) {
  demux::interpolateDirections(layout, tiles, columns, rows, band, out, outRows);
}
#endif

}  // namespace smx::algo::demux
