// Stages 3–4: pattern separation by steered derivatives (paper eqs 6–10) and division by the
// locally averaged colour (§4.3).
//   Directions: each projector's tile angles interpolated bilinearly (as wrapped differences)
//   to the pixel; unit vectors Q1.14 from the table. Presence: the nearest tile's.
//   Derivatives of S by matched 5-tap separable filters (below), row-streamed: the horizontal
//   filters of rows y − 2 … y + 2 are kept in a ring (int32), the vertical ones applied per pixel
//   in int64. D values are 2 × the derivative of S (32 × grey/px for the first order).
//   First order  D_c = v · (gx, gy)_c; v = the projector's own axis (no other pattern present)
//                or the normal of the other pattern's axis, signed towards this projector's
//                axis (so the surviving term keeps its sign).
//   Second order D_c = vᵀ H_c w; v, w the normals of the two other patterns' axes, signed
//                likewise.
//   Products of Q1.14 coefficients in int64, one shift each. Normalised value
//   N_c = D_c · (2^24 / average_c) >> 13: Q4.11 relative to the average colour, saturated to
//   int16.
#include <algorithm>
#include <array>
#include <cstdint>

#include "demux_kernels.hpp"
#include "smx/algo/fixed.hpp"

namespace smx::algo::demux {

namespace {

struct Vec {
  std::int32_t x;
  std::int32_t y;
};

// The normal of axis, turned so that its dot product with towards is non-negative.
Vec normalTowards(Vec axis, Vec towards) {
  Vec n{-axis.y, axis.x};
  const std::int64_t dot = std::int64_t{n.x} * towards.x + std::int64_t{n.y} * towards.y;
  if (dot < 0) {
    n = {-n.x, -n.y};
  }
  return n;
}

}  // namespace

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

// The three horizontal filters of one row of one channel, for x in [2, w − 3].
void filterRow(const std::int16_t* s, int w, std::int32_t* pre, std::int32_t* d1,
               std::int32_t* d2) {
  for (int x = 2; x + 2 < w; ++x) {
    const std::int32_t m2 = s[x - 2];
    const std::int32_t m1 = s[x - 1];
    const std::int32_t c0 = s[x];
    const std::int32_t p1 = s[x + 1];
    const std::int32_t p2 = s[x + 2];
    pre[x] = kPre[0] * (m2 + p2) + kPre[1] * (m1 + p1) + kPre[2] * c0;
    d1[x] = kD1[3] * (p1 - m1) + kD1[4] * (p2 - m2);
    d2[x] = kD2[0] * (m2 + p2) + kD2[2] * c0;
  }
}

// The vertical halves over rows y − 2 … y + 2 for a whole row, scaled by 2^-kRowShift (the rows
// and the output never overlap: restrict lets the loops vectorise).
constexpr int kRowShift = 13;

void verticalSmoothed(const std::int32_t* const (&rows)[5], std::int32_t* __restrict out, int w) {
  const std::int32_t* __restrict r0 = rows[0];
  const std::int32_t* __restrict r1 = rows[1];
  const std::int32_t* __restrict r2 = rows[2];
  const std::int32_t* __restrict r3 = rows[3];
  const std::int32_t* __restrict r4 = rows[4];
  for (int x = 2; x + 2 < w; ++x) {
    out[x] = (kPre[0] * (r0[x] + r4[x]) + kPre[1] * (r1[x] + r3[x]) + kPre[2] * r2[x]) >> kRowShift;
  }
}

void verticalDerivative(const std::int32_t* const (&rows)[5], std::int32_t* __restrict out, int w) {
  const std::int32_t* __restrict r0 = rows[0];
  const std::int32_t* __restrict r1 = rows[1];
  const std::int32_t* __restrict r3 = rows[3];
  const std::int32_t* __restrict r4 = rows[4];
  for (int x = 2; x + 2 < w; ++x) {
    out[x] = (kD1[3] * (r3[x] - r1[x]) + kD1[4] * (r4[x] - r0[x])) >> kRowShift;
  }
}

void verticalSecond(const std::int32_t* const (&rows)[5], std::int32_t* __restrict out, int w) {
  const std::int32_t* __restrict r0 = rows[0];
  const std::int32_t* __restrict r2 = rows[2];
  const std::int32_t* __restrict r4 = rows[4];
  for (int x = 2; x + 2 < w; ++x) {
    out[x] = (kD2[0] * (r0[x] + r4[x]) + kD2[2] * r2[x]) >> kRowShift;
  }
}

}  // namespace

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

void separate(const Planes3& smoothed, const DemuxLayout& layout, int projector,
              std::span<const TileDirection> tiles, std::span<const std::uint32_t> inverseColour,
              std::span<const TileInterp> columns, std::span<const TileInterp> rows,
              const UnitTable& units, const RowBlock& filtered, const RowBlock& derivs,
              std::span<const DirectionPlane> directions, const Planes3& separated,
              ImageView<std::uint8_t> order) {
  const int w = layout.width;
  const int h = layout.height;
  const int projectors = layout.projectors;
  const int tilesX = layout.tilesX();
  const std::size_t tileCount = layout.tileCount();
  const auto tileAt = [&](int p, int tx, int ty) -> const TileDirection& {
    return tiles[static_cast<std::size_t>(p) * tileCount +
                 static_cast<std::size_t>(ty) * static_cast<std::size_t>(tilesX) +
                 static_cast<std::size_t>(tx)];
  };
  constexpr int kNormShift = kInverseShift - kRelativeShift;
  // Row derivatives keep 2^-13 of the filter output (|value| < 2^16); steering by Q1.14
  // coefficients then shifts by 14 + 2 to reach D = 2·∂S (the filters' unit is 2^15 · 2·∂S).
  constexpr int kSteerShift = kUnitShift + kDerivShift - kRowShift;
  // D is 2·∂S = 32 × grey level per pixel.
  const std::int32_t minContrast = layout.params.minContrastGrey * 2 * kSmoothScale;
  // Tile columns are at most 8192 / 4.
  std::uint8_t presentBits[2048] = {};
  // Rows y − 2 … y + 2 live in slots (row + 5) % 5 of the ring; rows outside are never read.
  const auto slotOf = [](int row) { return (row + kFilterSlots) % kFilterSlots; };
  const auto fill = [&](int row) {
    for (int c = 0; c < 3; ++c) {
      const int slot = slotOf(row);
      filterRow(smoothed[static_cast<std::size_t>(c)].rowPtr(row), w,
                filtered.row(filterRowIndex(slot, c, 0)), filtered.row(filterRowIndex(slot, c, 1)),
                filtered.row(filterRowIndex(slot, c, 2)));
    }
  };
  for (int row = 0; row < 4 && row < h; ++row) {
    fill(row);
  }

  for (int y = 0; y < h; ++y) {
    if (y + 2 < h && y >= 2) {
      fill(y + 2);
    }
    std::int16_t* out[3] = {separated[0].rowPtr(y), separated[1].rowPtr(y), separated[2].rowPtr(y)};
    std::uint8_t* orderRow = order.rowPtr(y);
    const std::uint16_t* dirRows[kMaxProjectors] = {nullptr, nullptr, nullptr};
    for (int p = 0; p < projectors; ++p) {
      dirRows[p] = directions[static_cast<std::size_t>(p)].rowPtr(y);
    }
    const TileInterp& ry = rows[static_cast<std::size_t>(y)];
    const bool borderRow = y < 2 || y + 2 >= h;
    // Which projectors the nearest tile found, per tile column of this row.
    for (int tx = 0; tx < tilesX; ++tx) {
      unsigned bits = 0;
      for (int p = 0; p < projectors; ++p) {
        bits |= tileAt(p, tx, ry.nearest).present != 0 ? 1U << p : 0U;
      }
      presentBits[tx] = static_cast<std::uint8_t>(bits);
    }
    // Vertical halves of the separable filters over rows y − 2 … y + 2, per channel, for the
    // whole row (int32, vectorisable), scaled by 2^-13 into int32 range for the steering.
    const bool second = projectors == kMaxProjectors;
    for (std::size_t c = 0; c < 3; ++c) {
      const std::int32_t* pre[5] = {};
      const std::int32_t* d1[5] = {};
      const std::int32_t* d2[5] = {};
      for (int k = 0; k < 5; ++k) {
        const int slot = slotOf(y + k - 2);
        pre[k] = filtered.row(filterRowIndex(slot, static_cast<int>(c), 0));
        d1[k] = filtered.row(filterRowIndex(slot, static_cast<int>(c), 1));
        d2[k] = filtered.row(filterRowIndex(slot, static_cast<int>(c), 2));
      }
      verticalSmoothed(d1, derivs.row(derivativeRowIndex(c, kGx)), w);
      verticalDerivative(pre, derivs.row(derivativeRowIndex(c, kGy)), w);
      if (second) {
        verticalSmoothed(d2, derivs.row(derivativeRowIndex(c, kHxx)), w);
        verticalSecond(pre, derivs.row(derivativeRowIndex(c, kHyy)), w);
        verticalDerivative(d1, derivs.row(derivativeRowIndex(c, kHxy)), w);
      }
    }
    for (int x = 0; x < w; ++x) {
      const TileInterp& cx = columns[static_cast<std::size_t>(x)];
      if (borderRow || x < 2 || x + 2 >= w) {
        out[0][x] = out[1][x] = out[2][x] = 0;
        orderRow[x] = 0;
        continue;
      }
      const std::uint16_t ownAngle = dirRows[projector][x];
      const Vec own{units.cosOf(ownAngle), units.sinOf(ownAngle)};
      Vec others[2] = {{0, 0}, {0, 0}};
      int otherCount = 0;
      const unsigned presentHere = presentBits[cx.nearest];
      for (int q = 0; q < projectors; ++q) {
        if (q != projector && (presentHere & (1U << q)) != 0) {
          const std::uint16_t a = dirRows[q][x];
          others[otherCount++] = normalTowards({units.cosOf(a), units.sinOf(a)}, own);
        }
      }
      const std::size_t colourTile =
          (static_cast<std::size_t>(ry.nearest) * static_cast<std::size_t>(tilesX) +
           static_cast<std::size_t>(cx.nearest)) *
          3;
      std::int32_t raw[3] = {0, 0, 0};
      if (otherCount < 2) {
        const Vec v = otherCount == 0 ? own : others[0];
        for (std::size_t c = 0; c < 3; ++c) {
          raw[c] = (v.x * derivs.row(derivativeRowIndex(c, kGx))[x] +
                    v.y * derivs.row(derivativeRowIndex(c, kGy))[x]) >>
                   kSteerShift;
        }
      } else {
        // Q1.14 coefficients of the mixed derivative; |cxx| + |cxy| + |cyy| <= 2^15.
        const Vec& v = others[0];
        const Vec& u = others[1];
        const std::int32_t cxx = (v.x * u.x) >> kUnitShift;
        const std::int32_t cyy = (v.y * u.y) >> kUnitShift;
        const std::int32_t cxy = (v.x * u.y + v.y * u.x) >> kUnitShift;
        for (std::size_t c = 0; c < 3; ++c) {
          raw[c] = (cxx * derivs.row(derivativeRowIndex(c, kHxx))[x] +
                    cxy * derivs.row(derivativeRowIndex(c, kHxy))[x] +
                    cyy * derivs.row(derivativeRowIndex(c, kHyy))[x]) >>
                   kSteerShift;
        }
      }
      // Below the contrast floor (noise in shadows and on black) nothing is separated: the
      // division by a dark average would lift it over the relative threshold.
      const std::int32_t hi = std::max({raw[0], raw[1], raw[2]});
      const std::int32_t lo = std::min({raw[0], raw[1], raw[2]});
      for (std::size_t c = 0; c < 3; ++c) {
        out[c][x] = hi - lo < minContrast
                        ? std::int16_t{0}
                        : saturateCast<std::int16_t>(
                              (std::int64_t{raw[c]} * inverseColour[colourTile + c]) >> kNormShift);
      }
      orderRow[x] = otherCount < 2 ? 1 : 2;
    }
  }
}

}  // namespace smx::algo::demux
