#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

// Separable Gaussian blur of a row-major RGB float image, for the simulator's defocus models.
namespace smx::sim::detail {

using RgbF = std::array<float, 3>;

// What lies beyond the image: black (a projector shows nothing outside its image) or the edge
// pixel repeated (a camera image has no dark frame around it).
enum class Border { kBlack, kClampToEdge };

// Normalised taps w[k], k = −r … r, r = ⌈4σ⌉ (the truncated tail is below 1e-4 of the sum).
[[nodiscard]] inline std::vector<double> gaussianTaps(double sigma) {
  const int r = static_cast<int>(std::ceil(4.0 * sigma));
  std::vector<double> taps(static_cast<std::size_t>(2 * r + 1));
  double sum = 0.0;
  for (std::size_t j = 0; j < taps.size(); ++j) {
    const int k = static_cast<int>(j) - r;
    taps[j] = std::exp(-0.5 * k * k / (sigma * sigma));
    sum += taps[j];
  }
  for (double& w : taps) {
    w /= sum;
  }
  return taps;
}

// Blurs `image` (width × height) in place with a Gaussian of `sigma` pixels; σ ≤ 0 does nothing.
inline void gaussianBlur(std::vector<RgbF>& image, int width, int height, double sigma,
                         Border border) {
  if (!(sigma > 0.0) || width <= 0 || height <= 0) {
    return;
  }
  const std::vector<double> taps = gaussianTaps(sigma);
  const int r = static_cast<int>(taps.size() / 2);
  // One line (a row, or a column) at a time: copied into a buffer padded by r on both sides as
  // the border mode says, then convolved without bounds checks.
  const auto blurLines = [&](int lines, int length, std::size_t lineStep, std::size_t step) {
    std::vector<std::array<double, 3>> line(static_cast<std::size_t>(length + 2 * r));
    for (int l = 0; l < lines; ++l) {
      RgbF* first = image.data() + static_cast<std::size_t>(l) * lineStep;
      for (std::size_t k = 0; k < line.size(); ++k) {
        const int i = static_cast<int>(k) - r;
        auto& out = line[k];
        if ((i < 0 || i >= length) && border == Border::kBlack) {
          out = {};
          continue;
        }
        const RgbF& in = first[static_cast<std::size_t>(std::clamp(i, 0, length - 1)) * step];
        out = {in[0], in[1], in[2]};
      }
      for (int i = 0; i < length; ++i) {
        std::array<double, 3> acc{};
        for (std::size_t j = 0; j < taps.size(); ++j) {
          const auto& p = line[static_cast<std::size_t>(i) + j];
          acc[0] += taps[j] * p[0];
          acc[1] += taps[j] * p[1];
          acc[2] += taps[j] * p[2];
        }
        first[static_cast<std::size_t>(i) * step] = {
            static_cast<float>(acc[0]), static_cast<float>(acc[1]), static_cast<float>(acc[2])};
      }
    }
  };
  const auto w = static_cast<std::size_t>(width);
  blurLines(height, width, w, 1);  // rows
  blurLines(width, height, 1, w);  // columns
}

}  // namespace smx::sim::detail
