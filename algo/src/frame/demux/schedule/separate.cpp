// Stage 3, the schedule of separate() (reference: reference/separate.cpp): pattern separation
// by steered derivatives (paper eqs 6–10), every projector in one sweep over the rows. The
// division by the local colour (§4.3) is detectBoundaries()'.
//   Directions: each projector's tile angles interpolated bilinearly (as wrapped differences)
//   to the pixel; unit vectors Q1.14 from the table. Presence: the nearest tile's.
//   Derivatives of S by matched 5-tap separable filters (below), row-streamed: the horizontal
//   filters of rows y − 2 … y + 2 are kept in a ring (int32), the vertical ones applied per row.
//   They are the same for every projector, so each row's are formed once and every projector is
//   steered from them. D values are 2 × the derivative of S (32 × grey/px for the first order).
//   First order  D_c = v · (gx, gy)_c; v = the projector's own axis (no other pattern present)
//                or the normal of the other pattern's axis, signed towards this projector's
//                axis (so the surviving term keeps its sign).
//   Second order D_c = vᵀ H_c w; v, w the normals of the two other patterns' axes, signed
//                likewise.
//   Where max_c D − min_c D is below the contrast floor, D is 0 (noise in shadows and on black,
//   which the division by a dark average would lift over the relative threshold).
//   Since 0 <= S <= 16 × 255, every derivative (|·| <= 16 575 after the 2^-13 below), unit
//   vector, steering coefficient and D (|D| < 2^14) fits int16: the steering multiplies int16 by
//   int16 into int32, which the vector units do natively. The steering runs per span of pixels
//   whose nearest tiles hold the same other patterns, in branch-free loops that GCC vectorises.
#include <algorithm>
#include <array>
#include <cstdint>

#include "demux_kernels.hpp"

namespace smx::algo::demux {

namespace {

// The ring: rows y − 2 … y + 2 in slots (row + 5) % 5, per channel the prefilter, first and
// second derivative.
constexpr int kFilterSlots = 5;
static_assert(kFilterRows == std::size_t{kFilterSlots} * 3 * 3);
constexpr std::size_t filterRowIndex(int slot, int channel, int filter) {
  return (static_cast<std::size_t>(slot) * 3 + static_cast<std::size_t>(channel)) * 3 +
         static_cast<std::size_t>(filter);
}

// The int16 working rows: the current row's derivatives per channel, every projector's unit
// vectors along it, and per tile row and projector which other patterns each tile column holds;
// then the tile runs (first pixel and tile of each) and which derivative orders each tile column
// needs; then one projector's steering results.
enum DerivativeKind : int { kGx, kGy, kHxx, kHyy, kHxy, kDerivativeKinds };
constexpr std::size_t derivativeRowIndex(std::size_t channel, DerivativeKind kind) {
  return channel * kDerivativeKinds + static_cast<std::size_t>(kind);
}
constexpr std::size_t kUnitRows = std::size_t{3} * kDerivativeKinds;
constexpr std::size_t unitRowIndex(int projector, int component) {
  return kUnitRows + static_cast<std::size_t>(projector) * 2 + static_cast<std::size_t>(component);
}
constexpr std::size_t kOthersRows = kUnitRows + std::size_t{2} * kMaxProjectors;
constexpr std::size_t othersRowIndex(int projector) {
  return kOthersRows + static_cast<std::size_t>(projector);
}
constexpr std::size_t kRunStartRow = kOthersRows + kMaxProjectors;
constexpr std::size_t kRunTileRow = kRunStartRow + 1;
constexpr std::size_t kNeedsRow = kRunTileRow + 1;
constexpr std::size_t kSteerRows = kNeedsRow + 1;  // D per channel, then cxx, cxy, cyy
static_assert(kWorkRows == kSteerRows + 6);

// The horizontal prefilter and first derivative of one row of one channel, for x in [2, w − 3].
// Sums and differences of two S values fit int16 (0 <= S <= 16 × 255), and GCC multiplies int16
// by a constant into int32 in int16 lanes.
void filterRow(const std::int16_t* s, int w, std::int32_t* __restrict pre,
               std::int32_t* __restrict d1) {
  for (int x = 2; x + 2 < w; ++x) {
    const auto outer = static_cast<std::int16_t>(s[x - 2] + s[x + 2]);
    const auto inner = static_cast<std::int16_t>(s[x - 1] + s[x + 1]);
    const auto near = static_cast<std::int16_t>(s[x + 1] - s[x - 1]);
    const auto far = static_cast<std::int16_t>(s[x + 2] - s[x - 2]);
    pre[x] = kPre[0] * outer + kPre[1] * inner + kPre[2] * s[x];
    d1[x] = kD1[3] * near + kD1[4] * far;
  }
}

// The horizontal second derivative (needed with three projectors only).
void filterRowSecond(const std::int16_t* s, int w, std::int32_t* __restrict d2) {
  for (int x = 2; x + 2 < w; ++x) {
    const auto outer = static_cast<std::int16_t>(s[x - 2] + s[x + 2]);
    d2[x] = kD2[0] * outer + kD2[2] * s[x];
  }
}

// The vertical halves over rows y − 2 … y + 2 for x in [x0, x1), scaled by 2^-kRowShift into
// int16 (the rows and the output never overlap: restrict lets the loops vectorise).
constexpr int kRowShift = 13;

void verticalSmoothed(const std::int32_t* const (&rows)[5], std::int16_t* __restrict out, int x0,
                      int x1) {
  const std::int32_t* __restrict r0 = rows[0];
  const std::int32_t* __restrict r1 = rows[1];
  const std::int32_t* __restrict r2 = rows[2];
  const std::int32_t* __restrict r3 = rows[3];
  const std::int32_t* __restrict r4 = rows[4];
  for (int x = x0; x < x1; ++x) {
    out[x] = static_cast<std::int16_t>(
        (kPre[0] * (r0[x] + r4[x]) + kPre[1] * (r1[x] + r3[x]) + kPre[2] * r2[x]) >> kRowShift);
  }
}

void verticalDerivative(const std::int32_t* const (&rows)[5], std::int16_t* __restrict out, int x0,
                        int x1) {
  const std::int32_t* __restrict r0 = rows[0];
  const std::int32_t* __restrict r1 = rows[1];
  const std::int32_t* __restrict r3 = rows[3];
  const std::int32_t* __restrict r4 = rows[4];
  for (int x = x0; x < x1; ++x) {
    out[x] = static_cast<std::int16_t>((kD1[3] * (r3[x] - r1[x]) + kD1[4] * (r4[x] - r0[x])) >>
                                       kRowShift);
  }
}

void verticalSecond(const std::int32_t* const (&rows)[5], std::int16_t* __restrict out, int x0,
                    int x1) {
  const std::int32_t* __restrict r0 = rows[0];
  const std::int32_t* __restrict r2 = rows[2];
  const std::int32_t* __restrict r4 = rows[4];
  for (int x = x0; x < x1; ++x) {
    out[x] = static_cast<std::int16_t>((kD2[0] * (r0[x] + r4[x]) + kD2[2] * r2[x]) >> kRowShift);
  }
}

// The unit table's cos and sin of each entry in one word (cos low, sin high), so that a pixel's
// unit vector takes one scalar load (lookups do not vectorise).
constexpr std::uint32_t kUnitStep = 65536 / UnitTable::kEntries;

struct PackedUnits {
  std::array<std::uint32_t, UnitTable::kEntries> entries{};

  explicit PackedUnits(const UnitTable& units) {
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const auto angle = static_cast<std::uint16_t>(i * kUnitStep);
      entries[i] = static_cast<std::uint16_t>(units.cosOf(angle)) |
                   static_cast<std::uint32_t>(static_cast<std::uint16_t>(units.sinOf(angle)))
                       << 16U;
    }
  }
  // The nearest entry, as UnitTable takes it.
  [[nodiscard]] std::uint32_t of(std::uint16_t angle) const {
    return entries[((angle + kUnitStep / 2) / kUnitStep) % UnitTable::kEntries];
  }
};

void lookUpUnits(const std::uint16_t* angles, const PackedUnits& units, int w, std::int16_t* cosRow,
                 std::int16_t* sinRow) {
  for (int x = 2; x + 2 < w; ++x) {
    const std::uint32_t both = units.of(angles[x]);
    cosRow[x] = static_cast<std::int16_t>(both & 0xffffU);
    sinRow[x] = static_cast<std::int16_t>(both >> 16U);
  }
}

}  // namespace

namespace {

// One row's steering inputs and outputs, x in [2, w − 3]. The per-pixel loops below are written
// for GCC's vectoriser: straight-line int16/int32 arithmetic with selects instead of branches, no
// table lookups (the unit vectors are spread into rows of their own beforehand), and rows that
// never overlap (ivdep). GCC multiplies int16 by int16 into int32 in int16 lanes only when both
// factors are loaded as int16, so the steering coefficients of the second order and D go through
// rows of their own.
struct SteerRow {
  const std::int16_t* gx[3];
  const std::int16_t* gy[3];
  const std::int16_t* hxx[3];
  const std::int16_t* hyy[3];
  const std::int16_t* hxy[3];
  std::int16_t* cxx;  // the second order's steering coefficients
  std::int16_t* cxy;
  std::int16_t* cyy;
  std::int16_t* d[3];  // D per channel
};

// The unit vector rows (Q1.14) of one direction row.
struct UnitRows {
  const std::int16_t* cos;
  const std::int16_t* sin;
};

// Row derivatives keep 2^-13 of the filter output; steering by Q1.14 coefficients then shifts by
// 14 + 2 to reach D = 2·∂S (the filters' unit is 2^15 · 2·∂S).
constexpr int kSteerShift = kUnitShift + kDerivShift - kRowShift;

// The normal of another pattern's axis (cos, sin) steered along: (−sin, cos), turned if its dot
// product with the own axis is negative (|dot| <= 2^29: exact in int32), so that the surviving
// term keeps its sign. The loops below apply the turn as a sign of their products, whose
// factors then are all loaded int16 values.
[[gnu::always_inline]] inline bool turned(std::int16_t cos, std::int16_t sin, std::int16_t ownCos,
                                          std::int16_t ownSin) {
  return cos * ownSin - sin * ownCos < 0;
}

// First order along the own axis (no other pattern present) for x in [x0, x1).
void steerAlong(const SteerRow& r, UnitRows own, int x0, int x1) {
  const std::int16_t* vx = own.cos;
  const std::int16_t* vy = own.sin;
  for (std::size_t c = 0; c < 3; ++c) {
    const std::int16_t* gx = r.gx[c];
    const std::int16_t* gy = r.gy[c];
    std::int16_t* d = r.d[c];
    SMX_IVDEP
    for (int x = x0; x < x1; ++x) {
      d[x] = static_cast<std::int16_t>((vx[x] * gx[x] + vy[x] * gy[x]) >> kSteerShift);
    }
  }
}

// First order along the normal of the other pattern's axis.
void steerAcross(const SteerRow& r, UnitRows own, UnitRows other, int x0, int x1) {
  const std::int16_t* ownCos = own.cos;
  const std::int16_t* ownSin = own.sin;
  const std::int16_t* cos = other.cos;
  const std::int16_t* sin = other.sin;
  const std::int16_t* gx0 = r.gx[0];
  const std::int16_t* gx1 = r.gx[1];
  const std::int16_t* gx2 = r.gx[2];
  const std::int16_t* gy0 = r.gy[0];
  const std::int16_t* gy1 = r.gy[1];
  const std::int16_t* gy2 = r.gy[2];
  std::int16_t* d0 = r.d[0];
  std::int16_t* d1 = r.d[1];
  std::int16_t* d2 = r.d[2];
  SMX_IVDEP
  for (int x = x0; x < x1; ++x) {
    // v · g = ±(cos·gy − sin·gx)
    const bool turn = turned(cos[x], sin[x], ownCos[x], ownSin[x]);
    const std::int32_t e0 = cos[x] * gy0[x] - sin[x] * gx0[x];
    const std::int32_t e1 = cos[x] * gy1[x] - sin[x] * gx1[x];
    const std::int32_t e2 = cos[x] * gy2[x] - sin[x] * gx2[x];
    d0[x] = static_cast<std::int16_t>((turn ? -e0 : e0) >> kSteerShift);
    d1[x] = static_cast<std::int16_t>((turn ? -e1 : e1) >> kSteerShift);
    d2[x] = static_cast<std::int16_t>((turn ? -e2 : e2) >> kSteerShift);
  }
}

// Second order: the mixed derivative along the normals of both other patterns' axes.
void steerMixed(const SteerRow& r, UnitRows own, UnitRows first, UnitRows second, int x0, int x1) {
  const std::int16_t* ownCos = own.cos;
  const std::int16_t* ownSin = own.sin;
  const std::int16_t* cosV = first.cos;
  const std::int16_t* sinV = first.sin;
  const std::int16_t* cosU = second.cos;
  const std::int16_t* sinU = second.sin;
  std::int16_t* cxx = r.cxx;
  std::int16_t* cxy = r.cxy;
  std::int16_t* cyy = r.cyy;
  SMX_IVDEP
  for (int x = x0; x < x1; ++x) {
    // Q1.14 coefficients of the mixed derivative vᵀ H u, each <= |v|·|u| <= 2^14 (+ table
    // rounding): with v = ±(−sinV, cosV) and u = ±(−sinU, cosU), cxx = ±sinV·sinU,
    // cyy = ±cosV·cosU, cxy = ∓(sinV·cosU + cosV·sinU).
    const bool flip = turned(cosV[x], sinV[x], ownCos[x], ownSin[x]) !=
                      turned(cosU[x], sinU[x], ownCos[x], ownSin[x]);
    const std::int32_t xx = sinV[x] * sinU[x];
    const std::int32_t yy = cosV[x] * cosU[x];
    const std::int32_t xy = sinV[x] * cosU[x] + cosV[x] * sinU[x];
    cxx[x] = static_cast<std::int16_t>((flip ? -xx : xx) >> kUnitShift);
    cyy[x] = static_cast<std::int16_t>((flip ? -yy : yy) >> kUnitShift);
    cxy[x] = static_cast<std::int16_t>((flip ? xy : -xy) >> kUnitShift);
  }
  const auto mixed = [](std::int16_t xx, std::int16_t xy, std::int16_t yy, std::int16_t hxx,
                        std::int16_t hxy, std::int16_t hyy) {
    return static_cast<std::int16_t>((xx * hxx + xy * hxy + yy * hyy) >> kSteerShift);
  };
  std::int16_t* d0 = r.d[0];
  std::int16_t* d1 = r.d[1];
  std::int16_t* d2 = r.d[2];
  SMX_IVDEP
  for (int x = x0; x < x1; ++x) {
    d0[x] = mixed(cxx[x], cxy[x], cyy[x], r.hxx[0][x], r.hxy[0][x], r.hyy[0][x]);
    d1[x] = mixed(cxx[x], cxy[x], cyy[x], r.hxx[1][x], r.hxy[1][x], r.hyy[1][x]);
    d2[x] = mixed(cxx[x], cxy[x], cyy[x], r.hxx[2][x], r.hxy[2][x], r.hyy[2][x]);
  }
}

// Below the contrast floor nothing is separated.
void maskRow(const SteerRow& r, std::int32_t minContrast, int w, std::int16_t* const (&out)[3]) {
  const std::int16_t* d0 = r.d[0];
  const std::int16_t* d1 = r.d[1];
  const std::int16_t* d2 = r.d[2];
  SMX_IVDEP
  for (int x = 2; x + 2 < w; ++x) {
    const std::int16_t hi01 = d0[x] > d1[x] ? d0[x] : d1[x];
    const std::int16_t lo01 = d0[x] < d1[x] ? d0[x] : d1[x];
    const std::int16_t hi = hi01 > d2[x] ? hi01 : d2[x];
    const std::int16_t lo = lo01 < d2[x] ? lo01 : d2[x];
    const std::int16_t keep = hi - lo >= minContrast ? std::int16_t{-1} : std::int16_t{0};
    out[0][x] = static_cast<std::int16_t>(d0[x] & keep);
    out[1][x] = static_cast<std::int16_t>(d1[x] & keep);
    out[2][x] = static_cast<std::int16_t>(d2[x] & keep);
  }
}

}  // namespace

namespace {

// The runs of pixels in [2, w − 3] sharing the nearest tile column: run k starts at pixel
// starts[k] (starts[runs] = w − 2) and has tile column tiles[k].
struct TileRuns {
  const std::int16_t* starts;
  const std::int16_t* tiles;
  int runs;
};

TileRuns findRuns(std::span<const TileInterp> columns, int w, std::int16_t* starts,
                  std::int16_t* tiles) {
  int runs = 0;
  for (int x = 2; x + 2 < w; ++x) {
    const std::int16_t tx = columns[static_cast<std::size_t>(x)].nearest;
    if (runs == 0 || tiles[runs - 1] != tx) {
      starts[runs] = static_cast<std::int16_t>(x);
      tiles[runs++] = tx;
    }
  }
  starts[runs] = static_cast<std::int16_t>(w - 2);
  return {starts, tiles, runs};
}

// Per tile row: which other projectors each projector's nearest tile holds (bit q: projector q's
// pattern is present), and which derivative orders each tile column needs over all projectors.
constexpr int kNeedFirst = 1;
constexpr int kNeedSecond = 2;

void classifyTileRow(std::span<const TileDirection> tiles, const DemuxLayout& layout, int tileRow,
                     const RowBlock<std::int16_t>& work) {
  const int tilesX = layout.tilesX();
  const std::size_t tileCount = layout.tileCount();
  const std::size_t rowStart = static_cast<std::size_t>(tileRow) * static_cast<std::size_t>(tilesX);
  std::int16_t* needs = work.row(kNeedsRow);
  std::fill(needs, needs + tilesX, std::int16_t{0});
  for (int p = 0; p < layout.projectors; ++p) {
    std::int16_t* others = work.row(othersRowIndex(p));
    for (int tx = 0; tx < tilesX; ++tx) {
      unsigned bits = 0;
      int count = 0;
      for (int q = 0; q < layout.projectors; ++q) {
        const std::size_t t =
            static_cast<std::size_t>(q) * tileCount + rowStart + static_cast<std::size_t>(tx);
        if (q != p && tiles[t].present != 0) {
          bits |= 1U << q;
          ++count;
        }
      }
      others[tx] = static_cast<std::int16_t>(bits);
      needs[tx] = static_cast<std::int16_t>(needs[tx] | (count < 2 ? kNeedFirst : kNeedSecond));
    }
  }
}

// Calls f(x0, x1) for each longest span of runs whose tile columns need the order.
template <class F>
void forSpansNeeding(const TileRuns& runs, const std::int16_t* needs, int order, F&& f) {
  int k = 0;
  while (k < runs.runs) {
    if ((needs[runs.tiles[k]] & order) == 0) {
      ++k;
      continue;
    }
    int end = k + 1;
    while (end < runs.runs && (needs[runs.tiles[end]] & order) != 0) {
      ++end;
    }
    f(runs.starts[k], runs.starts[end]);
    k = end;
  }
}

// One projector's interior row, per span of runs whose tiles hold the same other patterns:
// there the derivative is fixed, so each span is one branch-free loop.
void steerRow(const SteerRow& steer, const std::int16_t* others, const UnitRows (&unitRows)[3],
              int projector, const TileRuns& runs, std::uint8_t* orderRow) {
  int k = 0;
  while (k < runs.runs) {
    const std::int16_t bits = others[runs.tiles[k]];
    int end = k + 1;
    while (end < runs.runs && others[runs.tiles[end]] == bits) {
      ++end;
    }
    const int x0 = runs.starts[k];
    const int x1 = runs.starts[end];
    int otherOf[2] = {0, 0};
    int otherCount = 0;
    for (int q = 0; q < kMaxProjectors; ++q) {
      if ((bits & (1 << q)) != 0) {
        otherOf[otherCount++] = q;
      }
    }
    const UnitRows own = unitRows[projector];
    if (otherCount == 0) {
      steerAlong(steer, own, x0, x1);
    } else if (otherCount == 1) {
      steerAcross(steer, own, unitRows[otherOf[0]], x0, x1);
    } else {
      steerMixed(steer, own, unitRows[otherOf[0]], unitRows[otherOf[1]], x0, x1);
    }
    std::fill(orderRow + x0, orderRow + x1, otherCount < 2 ? 1 : 2);
    k = end;
  }
}

void clearRow(const Planes3& separated, ImageView<std::uint8_t> order, int y, int x0, int x1) {
  for (const ImageView<std::int16_t>& plane : separated) {
    std::fill(plane.rowPtr(y) + x0, plane.rowPtr(y) + x1, std::int16_t{0});
  }
  std::fill(order.rowPtr(y) + x0, order.rowPtr(y) + x1, std::uint8_t{0});
}

}  // namespace

void separate(const Planes3& smoothed, const DemuxLayout& layout,
              std::span<const TileDirection> tiles, std::span<const TileInterp> columns,
              std::span<const TileInterp> rows, const UnitTable& units,
              const RowBlock<std::int32_t>& filtered, const RowBlock<std::int16_t>& work,
              std::span<const DirectionPlane> directions, std::span<const Planes3> separated,
              std::span<const ImageView<std::uint8_t>> order, RowRange band) {
  const int w = layout.width;
  const int h = layout.height;
  const int yBegin = std::max(band.begin, 0);
  const int yEnd = std::min(band.end, h);
  const int projectors = layout.projectors;
  // The second derivatives are only ever steered with three projectors.
  const bool second = projectors == kMaxProjectors;
  const auto slotOf = [](int row) { return (row + kFilterSlots) % kFilterSlots; };
  // Row `row` of S is read here, before row `row` − 2 of any output is written: an output may
  // take S's memory.
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
  // The ring as the whole image's sweep has it at row yBegin: rows yBegin − 2 … yBegin + 1 (rows
  // 0 … 3 before row 2, where the sweep starts filling).
  for (int row = std::max(yBegin - 2, 0); row < std::min(std::max(yBegin, 2) + 2, h); ++row) {
    fill(row);
  }

  const TileRuns runs = findRuns(columns, w, work.row(kRunStartRow), work.row(kRunTileRow));
  SteerRow steer{};
  for (std::size_t c = 0; c < 3; ++c) {
    steer.gx[c] = work.row(derivativeRowIndex(c, kGx));
    steer.gy[c] = work.row(derivativeRowIndex(c, kGy));
    steer.hxx[c] = work.row(derivativeRowIndex(c, kHxx));
    steer.hyy[c] = work.row(derivativeRowIndex(c, kHyy));
    steer.hxy[c] = work.row(derivativeRowIndex(c, kHxy));
    steer.d[c] = work.row(kSteerRows + c);
  }
  steer.cxx = work.row(kSteerRows + 3);
  steer.cxy = work.row(kSteerRows + 4);
  steer.cyy = work.row(kSteerRows + 5);
  // D is 2·∂S = 32 × grey level per pixel.
  const std::int32_t minContrast = layout.params.minContrastGrey * 2 * kSmoothScale;
  UnitRows unitRows[kMaxProjectors] = {};
  for (int q = 0; q < projectors; ++q) {
    unitRows[q] = {work.row(unitRowIndex(q, 0)), work.row(unitRowIndex(q, 1))};
  }
  const PackedUnits packedUnits(units);
  int casesRow = -1;

  for (int y = yBegin; y < yEnd; ++y) {
    if (y + 2 < h && y >= 2) {
      fill(y + 2);
    }
    if (y < 2 || y + 2 >= h) {
      for (int p = 0; p < projectors; ++p) {
        clearRow(separated[static_cast<std::size_t>(p)], order[static_cast<std::size_t>(p)], y, 0,
                 w);
      }
      continue;
    }
    const int tileRow = rows[static_cast<std::size_t>(y)].nearest;
    if (tileRow != casesRow) {
      classifyTileRow(tiles, layout, tileRow, work);
      casesRow = tileRow;
    }
    // Vertical halves of the separable filters over rows y − 2 … y + 2, per channel; only the
    // derivatives some pixel steers, where it does.
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
      const std::int16_t* needs = work.row(kNeedsRow);
      forSpansNeeding(runs, needs, kNeedFirst, [&](int x0, int x1) {
        verticalSmoothed(d1, work.row(derivativeRowIndex(c, kGx)), x0, x1);
        verticalDerivative(pre, work.row(derivativeRowIndex(c, kGy)), x0, x1);
      });
      forSpansNeeding(runs, needs, kNeedSecond, [&](int x0, int x1) {
        verticalSmoothed(d2, work.row(derivativeRowIndex(c, kHxx)), x0, x1);
        verticalSecond(pre, work.row(derivativeRowIndex(c, kHyy)), x0, x1);
        verticalDerivative(d1, work.row(derivativeRowIndex(c, kHxy)), x0, x1);
      });
    }
    for (int q = 0; q < projectors; ++q) {
      lookUpUnits(directions[static_cast<std::size_t>(q)].rowPtr(y), packedUnits, w,
                  work.row(unitRowIndex(q, 0)), work.row(unitRowIndex(q, 1)));
    }
    for (int p = 0; p < projectors; ++p) {
      const Planes3& planes = separated[static_cast<std::size_t>(p)];
      clearRow(planes, order[static_cast<std::size_t>(p)], y, 0, 2);
      clearRow(planes, order[static_cast<std::size_t>(p)], y, w - 2, w);
      steerRow(steer, work.row(othersRowIndex(p)), unitRows, p, runs,
               order[static_cast<std::size_t>(p)].rowPtr(y));
      std::int16_t* const out[3] = {planes[0].rowPtr(y), planes[1].rowPtr(y), planes[2].rowPtr(y)};
      maskRow(steer, minContrast, w, out);
    }
  }
}

#if SMX_DEMUX_AVX2
SMX_AVX2_TWIN void avx2::separate(
    const Planes3& smoothed, const DemuxLayout& layout, std::span<const TileDirection> tiles,
    std::span<const TileInterp> columns, std::span<const TileInterp> rows, const UnitTable& units,
    const RowBlock<std::int32_t>& filtered, const RowBlock<std::int16_t>& work,
    std::span<const DirectionPlane> directions, std::span<const Planes3> separated,
    std::span<const ImageView<std::uint8_t>> order, RowRange band) {
  demux::separate(smoothed, layout, tiles, columns, rows, units, filtered, work, directions,
                  separated, order, band);
}
#endif

}  // namespace smx::algo::demux
