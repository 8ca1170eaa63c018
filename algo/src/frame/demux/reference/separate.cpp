// Reference of stage 3b (demux_reference.hpp): per pixel the 5×5 derivative sums, then the
// directional derivative that cancels the other patterns present. Schedule:
// schedule/separate.cpp (a ring of horizontally filtered rows, derivatives in int16 rows
// shared by every projector, steering per span of pixels with the same other patterns).
#include <algorithm>
#include <array>
#include <cstdint>

#include "demux_reference.hpp"

namespace smx::algo::demux::reference {

namespace {

// 2^-13 of the separable filter sums Σ_{i,j} h_i v_j S(x + i − 2, y + j − 2) (i along x), which fit
// int16 (|·| <= 16 575 for 0 <= S <= 4080).
constexpr int kKeepShift = 13;

std::int32_t filtered(ImageView<const std::int16_t> s, int x, int y,
                      const std::array<std::int32_t, 5>& horizontal,
                      const std::array<std::int32_t, 5>& vertical) {
  std::int32_t sum = 0;
  for (std::size_t j = 0; j < 5; ++j) {
    for (std::size_t i = 0; i < 5; ++i) {
      sum +=
          horizontal[i] * vertical[j] * s(x + static_cast<int>(i) - 2, y + static_cast<int>(j) - 2);
    }
  }
  return sum >> kKeepShift;
}

// The derivatives of one channel at a pixel: ∇S and the Hessian, each 2^15 × 2·∂ >> 13.
struct Derivatives {
  std::int32_t gx;
  std::int32_t gy;
  std::int32_t hxx;
  std::int32_t hyy;
  std::int32_t hxy;
};

Derivatives derivativesAt(ImageView<const std::int16_t> s, int x, int y) {
  return {filtered(s, x, y, kD1, kPre), filtered(s, x, y, kPre, kD1), filtered(s, x, y, kD2, kPre),
          filtered(s, x, y, kPre, kD2), filtered(s, x, y, kD1, kD1)};
}

// Q1.14 × (2^15 · 2·∂ >> 13) >> 16 = D, 2·∂S (32 × grey level per pixel for the first order).
constexpr int kSteerShift = kUnitShift + kDerivShift - kKeepShift;

struct Unit {
  std::int32_t x;
  std::int32_t y;
};

// The normal (−sin φ, cos φ) of another pattern's axis, turned to the own axis' side.
Unit normalTowards(Unit axis, Unit own) {
  const Unit normal{-axis.y, axis.x};
  const bool turn = normal.x * own.x + normal.y * own.y < 0;
  return turn ? Unit{-normal.x, -normal.y} : normal;
}

}  // namespace

void separation(const Planes3& smoothed, const DemuxLayout& layout,
                std::span<const TileDirection> tiles, const UnitTable& units,
                std::span<const ConstDirectionPlane> directions, std::span<const Planes3> separated,
                std::span<const ImageView<std::uint8_t>> order) {
  const int w = layout.width;
  const int h = layout.height;
  const int t = layout.params.tilePx;
  const std::size_t tileCount = layout.tileCount();
  const std::int32_t minContrast = layout.params.minContrastGrey * 2 * kSmoothScale;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool border = x < 2 || y < 2 || x + 2 >= w || y + 2 >= h;
      Derivatives der[3] = {};
      if (!border) {
        for (std::size_t c = 0; c < 3; ++c) {
          der[c] = derivativesAt(smoothed[c], x, y);
        }
      }
      const std::size_t nearest =
          static_cast<std::size_t>(y / t) * static_cast<std::size_t>(layout.tilesX()) +
          static_cast<std::size_t>(x / t);
      for (int p = 0; p < layout.projectors; ++p) {
        const auto pi = static_cast<std::size_t>(p);
        if (border) {
          for (std::size_t c = 0; c < 3; ++c) {
            separated[pi][c](x, y) = 0;
          }
          order[pi](x, y) = 0;
          continue;
        }
        const auto unitOf = [&](int q) {
          const std::uint16_t angle = directions[static_cast<std::size_t>(q)](x, y);
          return Unit{units.cosOf(angle), units.sinOf(angle)};
        };
        const Unit own = unitOf(p);
        Unit normals[2] = {};
        int others = 0;
        for (int q = 0; q < layout.projectors; ++q) {
          if (q != p && tiles[static_cast<std::size_t>(q) * tileCount + nearest].present != 0) {
            normals[others++] = normalTowards(unitOf(q), own);
          }
        }
        std::int32_t d[3] = {};
        for (std::size_t c = 0; c < 3; ++c) {
          const Derivatives& g = der[c];
          if (others == 0) {  // eq 3: along the own axis
            d[c] = (own.x * g.gx + own.y * g.gy) >> kSteerShift;
          } else if (others == 1) {  // eqs 6, 7: along the other axis' normal
            d[c] = (normals[0].x * g.gx + normals[0].y * g.gy) >> kSteerShift;
          } else {  // eq 10: vᵀ H u along both normals, the coefficients rounded to Q1.14 first
            const Unit v = normals[0];
            const Unit u = normals[1];
            const std::int32_t cxx = (v.x * u.x) >> kUnitShift;
            const std::int32_t cyy = (v.y * u.y) >> kUnitShift;
            const std::int32_t cxy = (v.x * u.y + v.y * u.x) >> kUnitShift;
            d[c] = (cxx * g.hxx + cxy * g.hxy + cyy * g.hyy) >> kSteerShift;
          }
        }
        const std::int32_t hi = std::max({d[0], d[1], d[2]});
        const std::int32_t lo = std::min({d[0], d[1], d[2]});
        for (std::size_t c = 0; c < 3; ++c) {
          separated[pi][c](x, y) = static_cast<std::int16_t>(hi - lo >= minContrast ? d[c] : 0);
        }
        order[pi](x, y) = others < 2 ? 1 : 2;
      }
    }
  }
}

}  // namespace smx::algo::demux::reference
