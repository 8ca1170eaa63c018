#pragma once

// The demultiplexer's per-frame stages as plain scalar definitions: one function per stage, one
// file per function, each a loop over whole planes that reads like the equation it computes.
// They are the algorithm; src/frame/demux/schedule is how run() computes the same thing fast
// (row rings, int16 lanes, spans of equal cases, AVX2 twins). DemuxReference.* (tests/unit/
// demux_reference_test.cpp) runs every built schedule beside these on rendered frames and
// requires bit-identical output. Not on the production path: nothing calls them but the tests.
//
// Integer only, no allocation: every buffer is the caller's. Where a schedule's rounding is
// unusual (int16 high/low products, blends rounded down to even units) these compute the same
// integer result the plain way, in int32 or int64, and say so.
//
// §, eq: the paper, "Multi-Projector Color Structured-Light Vision", as cited per function;
// docs/architecture.md maps its sections to the code, docs/demux.md describes the stages.

#include <cstdint>
#include <span>

#include "demux_kernels.hpp"
#include "smx/algo/boundary_map.hpp"
#include "smx/algo/demux.hpp"
#include "smx/algo/image_view.hpp"

namespace smx::algo::demux::reference {

// Stage 1, noise reduction (§4.2 "Noise effect reduction": Gaussian smoothing), per channel c:
//   S_1(x, y) = Σ_{i,j ∈ −1..1} b_i b_j I_c(x + i, y + j),        b = (1, 2, 1)
//   S_k(x, y) = (Σ_{i,j} b_i b_j S_{k−1}(x + i, y + j) + 8) >> 4,  k = 2 … passes
// with coordinates clamped to the image (edges repeated); passes = 0 gives S = 16 · I_c.
// S is 16 × grey level. scratch: one plane of the image's size (passes >= 2).
void smooth(ConstRgbView image, int passes, const Planes3& out, ImageView<std::int16_t> scratch);

// Stage 2a, the gradient histogram of each tile (§3.2, the "doubly angled histogram"): at every
// sample (x, y multiples of histogramStride, the 5×5 support inside the image) and channel,
//   g = (Σ_{i,j} d1_i p_j S(x + i, y + j), Σ_{i,j} p_i d1_j S(x + i, y + j)) >> 15
// (p, d1: kPre, kD1, i, j ∈ −2..2), which is 2 × ∂S; where |g|² >= (2 · 16 · minGradientGrey)²,
// the doubled angle 2θ and |g| (gradientPolar()) add to the tile's bin b = round(2θ / 1024)
// mod 64: weights[b] += |g|, moments[b] += |g| · wrap(2θ − 1024 b). Tile-major, kBins per tile.
void histogram(const Planes3& smoothed, const DemuxLayout& layout, std::span<std::uint32_t> weights,
               std::span<std::int32_t> moments);

// Stage 2b, the encoding directions (§3.2: the angle window of π/2 stepped by π/4 over the
// histogram of a window of tiles, the peak refined locally, lobes assigned to projectors), per
// tile and projector, then the tile field cleaned up: growth of found tiles into absent ones, a
// 3×3 median of the offsets from the prediction (twice), and absent tiles filled from their
// neighbours (docs/demux.md stage 2 gives the rules and their reasons). out: projector-major,
// tileCount per projector. scratch: tileCount values.
void directions(const DemuxLayout& layout, std::span<const std::uint32_t> weights,
                std::span<const std::int32_t> moments, std::span<const std::uint16_t> predicted,
                std::span<TileDirection> out, std::span<std::uint16_t> scratch);

// Stage 3a, each projector's encoding direction per pixel (the φ of eqs 4–10): the tile angles
// interpolated bilinearly between tile centres (tile i's centre at pixel i·T + (T − 1)/2), as
// wrapped differences d from the lower-left tile's angle a00, weights in 1/256:
//   φ(x, y) = a00 + ((d10·wx·(256 − wy) + d01·(256 − wx)·wy + d11·wx·wy + 2^15) >> 16)
void interpolation(const DemuxLayout& layout, std::span<const TileDirection> tiles,
                   std::span<const DirectionPlane> out);

// Stage 3b, pattern separation by directional derivatives (§3.1, eqs 3–10), per projector and
// channel at every pixel 2 px inside the image (0 on that border, order 0):
//   no other pattern present:  D = ∂S/∂x_own                   (eq 3), order 1
//   one other pattern k:       D = ∂S/∂y_k                     (eqs 6, 7), order 1
//   two others k, l:           D = ∂²S/∂y_k ∂y_l               (eqs 9, 10), order 2
// where x = (cos φ, sin φ) (UnitTable, Q1.14), y = its normal (−sin φ, cos φ) turned towards
// the own axis, presence is the nearest tile's, and the derivatives are the matched 5-tap
// filters' (kPre, kD1, kD2: ∂x = d1 ⊗ p, ∂xx = d2 ⊗ p, ∂xy = d1 ⊗ d1) over S, each kept as
// (filter sum) >> 13, then steered: D = (v · ∇ or vᵀ H w) >> 16 (the second order's
// coefficients rounded to Q1.14 first). D = 0 where max_c D − min_c D < 32 · minContrastGrey.
void separation(const Planes3& smoothed, const DemuxLayout& layout,
                std::span<const TileDirection> tiles, const UnitTable& units,
                std::span<const ConstDirectionPlane> directions, std::span<const Planes3> separated,
                std::span<const ImageView<std::uint8_t>> order);

// Stages 4–5 for one projector, colour normalisation (§4.3: "divided by the locally averaged
// color") and boundary detection (§4.2: stripe segmentation by the derivative's colour class):
//   relative value r_c = (clamp(D_c, ±bound_c) · scale_c) >> 9, Q4.11 of the local colour,
//     scale_c = (2^24 / average_c + 8) >> 4 of the pixel's nearest tile (inverseTileColours),
//     bound_c = min(32767, (32767 << 9) / scale_c);
//   response n: first order D itself, second order D(p − u) − D(p + u) (u: the unit vector of
//     the direction in Q8, samples bilinear, blended rounding down to even units);
//   strengths: relative = max_c r(n) − min_c r(n), derivative = max_c n − min_c n;
//   a boundary where relative >= minStrength, >= its bilinear sample at p + u and > the one at
//     p − u (second order: and not below the samples at p ± 2u); class from the rising and the
//     falling channel, confidence from the third; sub-pixel offset from the parabola through the
//     derivative strength (first order) or the zero crossing of the response (second order).
// inverse: tileCount × 3 (inverseTileColours). Boundary rows 4 px inside the image.
void boundaries(const Planes3& separated, ImageView<const std::uint8_t> order,
                ConstDirectionPlane direction, const UnitTable& units,
                std::span<const std::uint32_t> inverse, const DemuxLayout& layout, int minStrength,
                const StrengthPlanes& strengths, BoundaryPlane out);

}  // namespace smx::algo::demux::reference
