// Stage 2a, the schedule of histogramTiles() (reference: reference/histogram.cpp).
//   Per sample pixel and channel (the paper histograms each channel's gradients: summing the
//   channels' tensors would cancel two patterns 90° apart): g by the matched 5-tap filters of
//   separate() (int32, then scaled to 2 × ∂S = 32 × grey/px, |g| < 2^14: central differences
//   bias the orientation of oblique stripes by degrees); gradients below minGradientGrey count
//   nothing, and the others, compacted per sample row so that their loop has no data-dependent
//   branch, contribute their doubled angle (BinAngle) with weight |g|, both from tables without
//   a division (gradientPolar(), gradient_polar.hpp: within 0.55 raw units and 0.54).
//   Per tile: a 64-bin histogram of the samples' doubled angles, weighted, and per bin the first
//   moment Σ w·(angle − bin centre) (int32: (tilePx / stride)² · 3 samples of weight < 2^14 and
//   offset ≤ 2^9 stay below 2^31 for the allowed (tilePx / stride)² ≤ 64).
#include <cstdint>

#include "demux_kernels.hpp"
#include "gradient_polar.hpp"

namespace smx::algo::demux {

namespace {
// histogramTiles()' working rows: the vertical prefilter and first derivative of a sample row,
// then the gradient (2 × ∂S) and its squared norm along it.
enum HistogramRow : std::size_t { kVertPre, kVertD1, kGradX, kGradY };

// The horizontal halves of the gradient at the samples x = first + i·step, i < count, into
// gx[i] and gy[i] (Step > 0 fixes the step at compile time, where the loop vectorises).
template <int Step>
void horizontalPass(const RowBlock<std::int32_t>& rows, int first, int step, int count) {
  const int s = Step > 0 ? Step : step;
  const std::int32_t* __restrict pre = rows.row(kVertPre) + first;
  const std::int32_t* __restrict d1 = rows.row(kVertD1) + first;
  std::int32_t* __restrict gx = rows.row(kGradX);
  std::int32_t* __restrict gy = rows.row(kGradY);
  for (int i = 0; i < count; ++i) {
    const int x = i * s;
    const std::int32_t accX =
        kD1[3] * (pre[x + 1] - pre[x - 1]) + kD1[4] * (pre[x + 2] - pre[x - 2]);
    const std::int32_t accY =
        kPre[0] * (d1[x - 2] + d1[x + 2]) + kPre[1] * (d1[x - 1] + d1[x + 1]) + kPre[2] * d1[x];
    gx[i] = accX >> kDerivShift;
    gy[i] = accY >> kDerivShift;
  }
}

// The matched 5-tap gradient (as separate() steers it) at the samples of row y, filtered
// vertically first, then horizontally: each row filter is shared by the samples around it, and
// the sums are those of the 5×5 kernel in another order, hence exact and equal.
void gradientRow(ImageView<const std::int16_t> plane, int y, int first, int step, int count,
                 const RowBlock<std::int32_t>& rows) {
  const int w = plane.width();
  const std::int16_t* r0 = plane.rowPtr(y - 2);
  const std::int16_t* r1 = plane.rowPtr(y - 1);
  const std::int16_t* r2 = plane.rowPtr(y);
  const std::int16_t* r3 = plane.rowPtr(y + 1);
  const std::int16_t* r4 = plane.rowPtr(y + 2);
  std::int32_t* __restrict pre = rows.row(kVertPre);
  std::int32_t* __restrict d1 = rows.row(kVertD1);
  for (int x = 0; x < w; ++x) {
    pre[x] = kPre[0] * (r0[x] + r4[x]) + kPre[1] * (r1[x] + r3[x]) + kPre[2] * r2[x];
    d1[x] = kD1[3] * (r3[x] - r1[x]) + kD1[4] * (r4[x] - r0[x]);
  }
  if (step == 2) {
    horizontalPass<2>(rows, first, step, count);
  } else {
    horizontalPass<0>(rows, first, step, count);
  }
}

}  // namespace

SampleGrid sampleGrid(const DemuxLayout& layout) {
  const int s = layout.params.histogramStride;
  return {s, (layout.width + s - 1) / s, (layout.height + s - 1) / s};
}

void histogramTiles(const Planes3& smoothed, const DemuxLayout& layout,
                    const RowBlock<std::int32_t>& rows, std::span<std::uint32_t> tileHistograms,
                    std::span<std::int32_t> tileMoments, int firstTileRow, int endTileRow) {
  const SampleGrid grid = sampleGrid(layout);
  const int w = layout.width;
  const int h = layout.height;
  const int s = grid.stride;
  const int t = layout.params.tilePx;
  const auto tilesX = static_cast<std::size_t>(layout.tilesX());
  const std::int32_t minGrad = layout.params.minGradientGrey * 2 * kSmoothScale;
  const std::int32_t minNorm2 = minGrad * minGrad;
  const int tilesY = layout.tilesY();
  const int ty0 = firstTileRow < 0 ? 0 : (firstTileRow > tilesY ? tilesY : firstTileRow);
  const int ty1 = endTileRow < ty0 ? ty0 : (endTileRow > tilesY ? tilesY : endTileRow);
  const std::size_t bandBegin = static_cast<std::size_t>(ty0) * tilesX * kBins;
  const std::size_t bandEnd = static_cast<std::size_t>(ty1) * tilesX * kBins;
  for (std::size_t i = bandBegin; i < bandEnd; ++i) {
    tileHistograms[i] = 0;
    tileMoments[i] = 0;
  }
  // Samples whose 5×5 support lies inside the image: x, y in [2, size − 3], multiples of s;
  // here the sample rows of the band's tile rows.
  const int first = (2 + s - 1) / s * s;
  const int count = w - 2 > first ? (w - 3 - first) / s + 1 : 0;
  const int bandTop = ty0 * t;
  const int yBegin = bandTop > first ? first + (bandTop - first + s - 1) / s * s : first;
  const int yEnd = ty1 * t < h - 2 ? ty1 * t : h - 2;
  for (int y = yBegin; y < yEnd; y += s) {
    for (std::size_t c = 0; c < 3; ++c) {
      gradientRow(smoothed[c], y, first, s, count, rows);
      // The samples at or above the threshold, compacted in place (n <= i), with their tile's
      // offset into the tile row's histograms: the loop below then has no branch that depends
      // on the data, and its iterations overlap.
      std::int32_t* __restrict gx = rows.row(kGradX);
      std::int32_t* __restrict gy = rows.row(kGradY);
      std::int32_t* __restrict binBase = rows.row(kVertPre);  // free after gradientRow()
      int n = 0;
      std::int32_t base = 0;
      int tileEnd = t;
      for (int i = 0; i < count; ++i) {
        const int x = first + i * s;
        while (x >= tileEnd) {
          tileEnd += t;
          base += kBins;
        }
        const std::int32_t sx = gx[i];
        const std::int32_t sy = gy[i];
        gx[n] = sx;
        gy[n] = sy;
        binBase[n] = base;
        n += sx * sx + sy * sy >= minNorm2 ? 1 : 0;
      }
      const std::size_t rowOffset = static_cast<std::size_t>(y / t) * tilesX * kBins;
      std::uint32_t* __restrict histograms = tileHistograms.data() + rowOffset;
      std::int32_t* __restrict moments = tileMoments.data() + rowOffset;
      for (int k = 0; k < n; ++k) {
        const GradientPolar polar = gradientPolar(gx[k], gy[k]);
        const std::uint32_t bin = ((polar.angle2 + kBinRaw / 2U) / kBinRaw) % kBins;
        const std::size_t at = static_cast<std::size_t>(binBase[k]) + bin;
        histograms[at] += static_cast<std::uint32_t>(polar.weight);
        moments[at] +=
            polar.weight * wrapDiff(polar.angle2, static_cast<std::uint16_t>(bin * kBinRaw));
      }
    }
  }
}

#if SMX_DEMUX_AVX2
SMX_AVX2_TWIN void avx2::histogramTiles(const Planes3& smoothed, const DemuxLayout& layout,
                                        const RowBlock<std::int32_t>& rows,
                                        std::span<std::uint32_t> tileHistograms,
                                        std::span<std::int32_t> tileMoments, int firstTileRow,
                                        int endTileRow) {
  demux::histogramTiles(smoothed, layout, rows, tileHistograms, tileMoments, firstTileRow,
                        endTileRow);
}
#endif

}  // namespace smx::algo::demux
