// Reference of stage 2a (demux_reference.hpp): each sample's gradient as the 5×5 sum of the
// matched filters, its doubled angle and magnitude, added to its tile's bin. Schedule:
// schedule/histogram.cpp (a vertical row pass, then a horizontal pass at the sample columns,
// the samples over the threshold compacted first).
#include <cstdint>

#include "demux_reference.hpp"
#include "gradient_polar.hpp"

namespace smx::algo::demux::reference {

namespace {

// 2 × ∂S along x and y at (x, y): Σ_{i,j} kD1_i kPre_j S(x + i − 2, y + j − 2) >> 15 and the
// transpose.
// |sum| <= 256 · 256 · 4080 < 2^31.
struct Gradient {
  std::int32_t x;
  std::int32_t y;
};

Gradient gradientAt(ImageView<const std::int16_t> s, int x, int y) {
  std::int32_t sumX = 0;
  std::int32_t sumY = 0;
  for (std::size_t j = 0; j < 5; ++j) {
    for (std::size_t i = 0; i < 5; ++i) {
      const std::int32_t v = s(x + static_cast<int>(i) - 2, y + static_cast<int>(j) - 2);
      sumX += kD1[i] * kPre[j] * v;
      sumY += kPre[i] * kD1[j] * v;
    }
  }
  return {sumX >> kDerivShift, sumY >> kDerivShift};
}

}  // namespace

void histogram(const Planes3& smoothed, const DemuxLayout& layout, std::span<std::uint32_t> weights,
               std::span<std::int32_t> moments) {
  const int s = layout.params.histogramStride;
  const int t = layout.params.tilePx;
  const auto tilesX = static_cast<std::size_t>(layout.tilesX());
  const std::int32_t minGrad = layout.params.minGradientGrey * 2 * kSmoothScale;
  for (std::uint32_t& w : weights) {
    w = 0;
  }
  for (std::int32_t& m : moments) {
    m = 0;
  }
  for (int y = 0; y < layout.height; y += s) {
    for (int x = 0; x < layout.width; x += s) {
      if (x < 2 || y < 2 || x + 2 >= layout.width || y + 2 >= layout.height) {
        continue;  // the 5×5 support leaves the image
      }
      const std::size_t tile =
          static_cast<std::size_t>(y / t) * tilesX + static_cast<std::size_t>(x / t);
      for (const ImageView<std::int16_t>& plane : smoothed) {
        const Gradient g = gradientAt(plane, x, y);
        if (g.x * g.x + g.y * g.y < minGrad * minGrad) {
          continue;
        }
        const GradientPolar polar = gradientPolar(g.x, g.y);
        const std::uint32_t bin = ((polar.angle2 + kBinRaw / 2U) / kBinRaw) % kBins;
        const std::size_t at = tile * kBins + bin;
        weights[at] += static_cast<std::uint32_t>(polar.weight);
        moments[at] +=
            polar.weight * wrapDiff(polar.angle2, static_cast<std::uint16_t>(bin * kBinRaw));
      }
    }
  }
}

}  // namespace smx::algo::demux::reference
