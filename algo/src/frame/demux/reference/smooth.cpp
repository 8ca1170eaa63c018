// Reference of stage 1 (demux_reference.hpp): the 3×3 binomial kernel over clamped
// coordinates, written as the 2-D sum. Schedule: schedule/smooth.cpp (separable passes, the
// first straight from the interleaved RGB rows).
#include <cstdint>

#include "demux_reference.hpp"

namespace smx::algo::demux::reference {

namespace {

constexpr std::int32_t kBinomial[3] = {1, 2, 1};

int clampTo(int v, int size) {
  return v < 0 ? 0 : (v >= size ? size - 1 : v);
}

std::int32_t channelOf(const Rgb8& pixel, int channel) {
  return channel == 0 ? pixel.r : (channel == 1 ? pixel.g : pixel.b);
}

// Σ_{i,j} b_i b_j v(x + i, y + j), coordinates clamped.
template <class Value>
std::int32_t binomialSum(int x, int y, int w, int h, Value value) {
  std::int32_t sum = 0;
  for (int j = -1; j <= 1; ++j) {
    for (int i = -1; i <= 1; ++i) {
      sum += kBinomial[i + 1] * kBinomial[j + 1] * value(clampTo(x + i, w), clampTo(y + j, h));
    }
  }
  return sum;
}

}  // namespace

void smooth(ConstRgbView image, int passes, const Planes3& out, ImageView<std::int16_t> scratch) {
  const int w = image.width();
  const int h = image.height();
  for (int c = 0; c < 3; ++c) {
    const ImageView<std::int16_t>& plane = out[static_cast<std::size_t>(c)];
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (passes == 0) {
          plane(x, y) = static_cast<std::int16_t>(kSmoothScale * channelOf(image(x, y), c));
        } else {
          // The kernel sums to 16: S_1 is 16 × grey, exact.
          plane(x, y) = static_cast<std::int16_t>(
              binomialSum(x, y, w, h, [&](int u, int v) { return channelOf(image(u, v), c); }));
        }
      }
    }
    for (int pass = 1; pass < passes; ++pass) {
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          scratch(x, y) = plane(x, y);
        }
      }
      // Later passes keep the scale: / 16, rounded half up.
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const std::int32_t sum =
              binomialSum(x, y, w, h, [&](int u, int v) { return std::int32_t{scratch(u, v)}; });
          plane(x, y) = static_cast<std::int16_t>((sum + 8) >> 4);
        }
      }
    }
  }
}

}  // namespace smx::algo::demux::reference
