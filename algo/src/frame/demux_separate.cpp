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
//   Products of Q1.14 coefficients in int32 (they fit), one shift each. Normalised value
//   N_c = D_c · (2^24 / average_c) >> 13: Q4.11 relative to the average colour, saturated to
//   int16 (D_c clamped first to where it saturates anyway, so the product fits in int32).
//   The steering runs per run of pixels sharing the nearest tile, in branch-free loops that GCC
//   vectorises; the derivative rows and unit vectors it reads are formed once per row.
#include <algorithm>
#include <array>
#include <cstdint>

#include "demux_kernels.hpp"
#include "smx/algo/fixed.hpp"

namespace smx::algo::demux {

namespace {

// The horizontal prefilter and first derivative of one row of one channel, for x in [2, w − 3].
void filterRow(const std::int16_t* s, int w, std::int32_t* pre, std::int32_t* d1) {
  for (int x = 2; x + 2 < w; ++x) {
    const std::int32_t m2 = s[x - 2];
    const std::int32_t m1 = s[x - 1];
    const std::int32_t c0 = s[x];
    const std::int32_t p1 = s[x + 1];
    const std::int32_t p2 = s[x + 2];
    pre[x] = kPre[0] * (m2 + p2) + kPre[1] * (m1 + p1) + kPre[2] * c0;
    d1[x] = kD1[3] * (p1 - m1) + kD1[4] * (p2 - m2);
  }
}

// The horizontal second derivative (needed with three projectors only).
void filterRowSecond(const std::int16_t* s, int w, std::int32_t* d2) {
  for (int x = 2; x + 2 < w; ++x) {
    d2[x] = kD2[0] * (s[x - 2] + s[x + 2]) + kD2[2] * s[x];
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

namespace {

// One row's steering inputs and outputs, x in [2, w − 3]. The per-pixel loops below are written
// for GCC's vectoriser: straight-line int32 arithmetic with selects instead of branches, no
// table lookups (the unit vectors are looked up beforehand into rows of their own), and the
// int16 outputs cannot alias the int32 inputs.
struct SteerRow {
  const std::int32_t* gx[3];
  const std::int32_t* gy[3];
  const std::int32_t* hxx[3];
  const std::int32_t* hyy[3];
  const std::int32_t* hxy[3];
  std::int16_t* out[3];
};

// The unit vector rows (Q1.14) of one direction row, looked up once per row.
struct UnitRows {
  const std::int32_t* cos;
  const std::int32_t* sin;
};

void lookUpUnits(const std::uint16_t* angles, const UnitTable& units, int w, std::int32_t* cosRow,
                 std::int32_t* sinRow) {
  for (int x = 2; x + 2 < w; ++x) {
    cosRow[x] = units.cosOf(angles[x]);
    sinRow[x] = units.sinOf(angles[x]);
  }
}

// Row derivatives keep 2^-13 of the filter output (|value| < 2^16); steering by Q1.14
// coefficients then shifts by 14 + 2 to reach D = 2·∂S (the filters' unit is 2^15 · 2·∂S).
constexpr int kSteerShift = kUnitShift + kDerivShift - kRowShift;

// Division by the tile's average colour: N = D · inverse >> kNormShift saturated to int16, where
// the product is taken in int64. D is first clamped to ±limit, the smallest magnitude that
// saturates anyway (limit · inverse ≥ 2^28), so that the product fits in int32 (inverse <= 2^24
// / kColourFloor = 2^17, hence limit · inverse < 2^28 + 2^17) and the result is the same.
constexpr int kNormShift = kInverseShift - kRelativeShift;

struct TileColour {
  std::int32_t inverse[3];
  std::int32_t limit[3];
};

TileColour tileColour(const std::uint32_t* inverse) {
  constexpr std::int64_t kSaturating = std::int64_t{1} << (15 + kNormShift);
  TileColour t{};
  for (std::size_t c = 0; c < 3; ++c) {
    const std::int64_t inv = inverse[c];
    t.inverse[c] = static_cast<std::int32_t>(inv);
    t.limit[c] =
        inv == 0 ? std::int32_t{1} << 30 : static_cast<std::int32_t>((kSaturating + inv - 1) / inv);
  }
  return t;
}

// Values, not references (std::clamp's), so that GCC if-converts the selects.
[[gnu::always_inline]] inline std::int32_t clampTo(std::int32_t v, std::int32_t lo,
                                                   std::int32_t hi) {
  const std::int32_t upper = v > hi ? hi : v;
  return upper < lo ? lo : upper;
}

// Below the contrast floor (noise in shadows and on black) nothing is separated: the division
// by a dark average would lift it over the relative threshold.
[[gnu::always_inline]] inline void store(std::int16_t* __restrict const (&out)[3], int x,
                                         std::int32_t r0, std::int32_t r1, std::int32_t r2,
                                         const TileColour& colour, std::int32_t minContrast) {
  const std::int32_t hi01 = r0 > r1 ? r0 : r1;
  const std::int32_t lo01 = r0 < r1 ? r0 : r1;
  const std::int32_t hi = hi01 > r2 ? hi01 : r2;
  const std::int32_t lo = lo01 < r2 ? lo01 : r2;
  const std::int32_t keep = hi - lo < minContrast ? 0 : 1;
  const std::int32_t raw[3] = {r0, r1, r2};
  for (std::size_t c = 0; c < 3; ++c) {
    const std::int32_t product =
        clampTo(raw[c], -colour.limit[c], colour.limit[c]) * colour.inverse[c];
    out[c][x] = static_cast<std::int16_t>(clampTo(product >> kNormShift, -32768, 32767) * keep);
  }
}

// The normal (−sin, cos) of a unit vector, turned if its dot product with the own axis is
// negative (|dot| <= 2^29: exact in int32), so that the surviving term keeps its sign.
struct Normal {
  std::int32_t x;
  std::int32_t y;
};
[[gnu::always_inline]] inline Normal normalTowards(std::int32_t cos, std::int32_t sin,
                                                   std::int32_t ownCos, std::int32_t ownSin) {
  const std::int32_t dot = -sin * ownCos + cos * ownSin;
  return dot < 0 ? Normal{sin, -cos} : Normal{-sin, cos};
}

// First order along the own axis (no other pattern present) for x in [x0, x1).
void steerAlong(const SteerRow& r, UnitRows own, int x0, int x1, const TileColour& colour,
                std::int32_t minContrast) {
  const std::int32_t* __restrict vx = own.cos;
  const std::int32_t* __restrict vy = own.sin;
  const std::int32_t* __restrict gx0 = r.gx[0];
  const std::int32_t* __restrict gx1 = r.gx[1];
  const std::int32_t* __restrict gx2 = r.gx[2];
  const std::int32_t* __restrict gy0 = r.gy[0];
  const std::int32_t* __restrict gy1 = r.gy[1];
  const std::int32_t* __restrict gy2 = r.gy[2];
  std::int16_t* __restrict const out[3] = {r.out[0], r.out[1], r.out[2]};
  for (int x = x0; x < x1; ++x) {
    store(out, x, (vx[x] * gx0[x] + vy[x] * gy0[x]) >> kSteerShift,
          (vx[x] * gx1[x] + vy[x] * gy1[x]) >> kSteerShift,
          (vx[x] * gx2[x] + vy[x] * gy2[x]) >> kSteerShift, colour, minContrast);
  }
}

// First order along the normal of the other pattern's axis.
void steerAcross(const SteerRow& r, UnitRows own, UnitRows other, int x0, int x1,
                 const TileColour& colour, std::int32_t minContrast) {
  const std::int32_t* __restrict ownCos = own.cos;
  const std::int32_t* __restrict ownSin = own.sin;
  const std::int32_t* __restrict cos = other.cos;
  const std::int32_t* __restrict sin = other.sin;
  const std::int32_t* __restrict gx0 = r.gx[0];
  const std::int32_t* __restrict gx1 = r.gx[1];
  const std::int32_t* __restrict gx2 = r.gx[2];
  const std::int32_t* __restrict gy0 = r.gy[0];
  const std::int32_t* __restrict gy1 = r.gy[1];
  const std::int32_t* __restrict gy2 = r.gy[2];
  std::int16_t* __restrict const out[3] = {r.out[0], r.out[1], r.out[2]};
  for (int x = x0; x < x1; ++x) {
    const Normal v = normalTowards(cos[x], sin[x], ownCos[x], ownSin[x]);
    store(out, x, (v.x * gx0[x] + v.y * gy0[x]) >> kSteerShift,
          (v.x * gx1[x] + v.y * gy1[x]) >> kSteerShift,
          (v.x * gx2[x] + v.y * gy2[x]) >> kSteerShift, colour, minContrast);
  }
}

// Second order: the mixed derivative along the normals of both other patterns' axes.
void steerMixed(const SteerRow& r, UnitRows own, UnitRows first, UnitRows second, int x0, int x1,
                const TileColour& colour, std::int32_t minContrast) {
  const std::int32_t* __restrict ownCos = own.cos;
  const std::int32_t* __restrict ownSin = own.sin;
  const std::int32_t* __restrict cosV = first.cos;
  const std::int32_t* __restrict sinV = first.sin;
  const std::int32_t* __restrict cosU = second.cos;
  const std::int32_t* __restrict sinU = second.sin;
  const std::int32_t* __restrict hxx0 = r.hxx[0];
  const std::int32_t* __restrict hxx1 = r.hxx[1];
  const std::int32_t* __restrict hxx2 = r.hxx[2];
  const std::int32_t* __restrict hyy0 = r.hyy[0];
  const std::int32_t* __restrict hyy1 = r.hyy[1];
  const std::int32_t* __restrict hyy2 = r.hyy[2];
  const std::int32_t* __restrict hxy0 = r.hxy[0];
  const std::int32_t* __restrict hxy1 = r.hxy[1];
  const std::int32_t* __restrict hxy2 = r.hxy[2];
  std::int16_t* __restrict const out[3] = {r.out[0], r.out[1], r.out[2]};
  for (int x = x0; x < x1; ++x) {
    const Normal v = normalTowards(cosV[x], sinV[x], ownCos[x], ownSin[x]);
    const Normal u = normalTowards(cosU[x], sinU[x], ownCos[x], ownSin[x]);
    // Q1.14 coefficients of the mixed derivative; |cxx| + |cxy| + |cyy| <= 2^15.
    const std::int32_t cxx = (v.x * u.x) >> kUnitShift;
    const std::int32_t cyy = (v.y * u.y) >> kUnitShift;
    const std::int32_t cxy = (v.x * u.y + v.y * u.x) >> kUnitShift;
    store(out, x, (cxx * hxx0[x] + cxy * hxy0[x] + cyy * hyy0[x]) >> kSteerShift,
          (cxx * hxx1[x] + cxy * hxy1[x] + cyy * hyy1[x]) >> kSteerShift,
          (cxx * hxx2[x] + cxy * hxy2[x] + cyy * hyy2[x]) >> kSteerShift, colour, minContrast);
  }
}

}  // namespace

namespace {

// Which other projectors the nearest tile found, per tile column of one tile row, and what the
// row therefore needs.
struct RowCases {
  std::uint8_t others[2048] = {};  // bit q: projector q is present (tile columns <= 8192 / 4)
  unsigned anyOthers = 0;          // the union of the bits
  bool needFirst = false;          // some tile column has at most one other pattern
  bool needSecond = false;         // some tile column has two
};

void classifyRow(std::span<const TileDirection> tiles, const DemuxLayout& layout, int projector,
                 int tileRow, RowCases& cases) {
  const int tilesX = layout.tilesX();
  const std::size_t tileCount = layout.tileCount();
  cases.anyOthers = 0;
  cases.needFirst = cases.needSecond = false;
  for (int tx = 0; tx < tilesX; ++tx) {
    unsigned bits = 0;
    int count = 0;
    for (int q = 0; q < layout.projectors; ++q) {
      const std::size_t t = static_cast<std::size_t>(q) * tileCount +
                            static_cast<std::size_t>(tileRow) * static_cast<std::size_t>(tilesX) +
                            static_cast<std::size_t>(tx);
      if (q != projector && tiles[t].present != 0) {
        bits |= 1U << q;
        ++count;
      }
    }
    cases.others[tx] = static_cast<std::uint8_t>(bits);
    cases.anyOthers |= bits;
    (count < 2 ? cases.needFirst : cases.needSecond) = true;
  }
}

// One interior row, per run of pixels sharing the nearest tile: there the patterns present
// (hence the derivative) and the colour are fixed, so each run is one branch-free loop.
void steerRow(const SteerRow& steer, const RowCases& cases, const UnitRows (&unitRows)[3],
              int projector, std::span<const TileInterp> columns,
              const std::uint32_t* tileRowInverse, int w, std::int32_t minContrast,
              std::uint8_t* orderRow) {
  int x0 = 2;
  while (x0 + 2 < w) {
    const int tx = columns[static_cast<std::size_t>(x0)].nearest;
    int x1 = x0 + 1;
    while (x1 + 2 < w && columns[static_cast<std::size_t>(x1)].nearest == tx) {
      ++x1;
    }
    int others[2] = {0, 0};
    int otherCount = 0;
    for (int q = 0; q < kMaxProjectors; ++q) {
      if ((cases.others[tx] & (1U << q)) != 0) {
        others[otherCount++] = q;
      }
    }
    const TileColour colour = tileColour(tileRowInverse + static_cast<std::size_t>(tx) * 3);
    const UnitRows own = unitRows[projector];
    if (otherCount == 0) {
      steerAlong(steer, own, x0, x1, colour, minContrast);
    } else if (otherCount == 1) {
      steerAcross(steer, own, unitRows[others[0]], x0, x1, colour, minContrast);
    } else {
      steerMixed(steer, own, unitRows[others[0]], unitRows[others[1]], x0, x1, colour, minContrast);
    }
    std::fill(orderRow + x0, orderRow + x1, otherCount < 2 ? 1 : 2);
    x0 = x1;
  }
}

}  // namespace

void separate(const Planes3& smoothed, const DemuxLayout& layout, int projector,
              std::span<const TileDirection> tiles, std::span<const std::uint32_t> inverseColour,
              std::span<const TileInterp> columns, std::span<const TileInterp> rows,
              const UnitTable& units, const RowBlock& filtered, const RowBlock& derivs,
              std::span<const DirectionPlane> directions, const Planes3& separated,
              ImageView<std::uint8_t> order) {
  const int w = layout.width;
  const int h = layout.height;
  const int projectors = layout.projectors;
  // The second derivatives are only ever steered with three projectors.
  const bool second = projectors == kMaxProjectors;
  // D is 2·∂S = 32 × grey level per pixel.
  const std::int32_t minContrast = layout.params.minContrastGrey * 2 * kSmoothScale;
  // Rows y − 2 … y + 2 live in slots (row + 5) % 5 of the ring; rows outside are never read.
  const auto slotOf = [](int row) { return (row + kFilterSlots) % kFilterSlots; };
  const auto fill = [&](int row) {
    for (int c = 0; c < 3; ++c) {
      const int slot = slotOf(row);
      const std::int16_t* s = smoothed[static_cast<std::size_t>(c)].rowPtr(row);
      filterRow(s, w, filtered.row(filterRowIndex(slot, c, 0)),
                filtered.row(filterRowIndex(slot, c, 1)));
      if (second) {
        filterRowSecond(s, w, filtered.row(filterRowIndex(slot, c, 2)));
      }
    }
  };
  for (int row = 0; row < 4 && row < h; ++row) {
    fill(row);
  }

  SteerRow steer{};
  for (std::size_t c = 0; c < 3; ++c) {
    steer.gx[c] = derivs.row(derivativeRowIndex(c, kGx));
    steer.gy[c] = derivs.row(derivativeRowIndex(c, kGy));
    steer.hxx[c] = derivs.row(derivativeRowIndex(c, kHxx));
    steer.hyy[c] = derivs.row(derivativeRowIndex(c, kHyy));
    steer.hxy[c] = derivs.row(derivativeRowIndex(c, kHxy));
  }
  UnitRows unitRows[kMaxProjectors] = {};
  for (int q = 0; q < projectors; ++q) {
    unitRows[q] = {derivs.row(unitRowIndex(q, 0)), derivs.row(unitRowIndex(q, 1))};
  }
  RowCases cases;
  int casesRow = -1;

  for (int y = 0; y < h; ++y) {
    if (y + 2 < h && y >= 2) {
      fill(y + 2);
    }
    std::int16_t* out[3] = {separated[0].rowPtr(y), separated[1].rowPtr(y), separated[2].rowPtr(y)};
    std::uint8_t* orderRow = order.rowPtr(y);
    if (y < 2 || y + 2 >= h) {
      for (std::int16_t* row : out) {
        std::fill_n(row, w, std::int16_t{0});
      }
      std::fill_n(orderRow, w, std::uint8_t{0});
      continue;
    }
    for (std::size_t c = 0; c < 3; ++c) {
      steer.out[c] = out[c];
      out[c][0] = out[c][1] = out[c][w - 2] = out[c][w - 1] = 0;
    }
    orderRow[0] = orderRow[1] = orderRow[w - 2] = orderRow[w - 1] = 0;
    const int tileRow = rows[static_cast<std::size_t>(y)].nearest;
    if (tileRow != casesRow) {
      classifyRow(tiles, layout, projector, tileRow, cases);
      casesRow = tileRow;
    }
    // Vertical halves of the separable filters over rows y − 2 … y + 2, per channel, for the
    // whole row (int32, vectorisable), scaled by 2^-13 into int32 range for the steering; only
    // the derivatives some pixel of the row steers.
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
      if (cases.needFirst) {
        verticalSmoothed(d1, derivs.row(derivativeRowIndex(c, kGx)), w);
        verticalDerivative(pre, derivs.row(derivativeRowIndex(c, kGy)), w);
      }
      if (cases.needSecond) {
        verticalSmoothed(d2, derivs.row(derivativeRowIndex(c, kHxx)), w);
        verticalSecond(pre, derivs.row(derivativeRowIndex(c, kHyy)), w);
        verticalDerivative(d1, derivs.row(derivativeRowIndex(c, kHxy)), w);
      }
    }
    // The unit vectors of the own axis and of the others present somewhere along the row.
    for (int q = 0; q < projectors; ++q) {
      if (q == projector || (cases.anyOthers & (1U << q)) != 0) {
        lookUpUnits(directions[static_cast<std::size_t>(q)].rowPtr(y), units, w,
                    derivs.row(unitRowIndex(q, 0)), derivs.row(unitRowIndex(q, 1)));
      }
    }
    const std::uint32_t* tileRowInverse =
        inverseColour.data() +
        static_cast<std::size_t>(tileRow) * static_cast<std::size_t>(layout.tilesX()) * 3;
    steerRow(steer, cases, unitRows, projector, columns, tileRowInverse, w, minContrast, orderRow);
  }
}

}  // namespace smx::algo::demux
