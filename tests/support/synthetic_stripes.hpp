#pragma once

#include <cmath>
#include <cstddef>
#include <numbers>
#include <random>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/algo/stripe_code.hpp"

// Test support: clean superpositions of the stripe pattern, computed analytically (no renderer),
// for unit tests of the per-frame kernels on host and aarch64.
namespace smx::test {

// A pattern as a projector shows it: stripe ⌊s⌋ of width stripePx along (cos a, sin a) through
// the image centre, s = 99 there; it adds `level` to its colour's channel.
struct SyntheticPattern {
  double angleDeg;
  double stripePx;
  double level = 110;
};

inline double stripeAt(const SyntheticPattern& p, int w, int h, double x, double y) {
  const double a = p.angleDeg * std::numbers::pi / 180.0;
  return ((x - (w - 1) / 2.0) * std::cos(a) + (y - (h - 1) / 2.0) * std::sin(a)) / p.stripePx +
         99.0;
}

// The patterns added over an ambient level; each pixel averages 4 × 4 samples, as a camera
// integrates over its pixel.
inline std::vector<algo::Rgb8> superpose(const std::vector<SyntheticPattern>& patterns, int w,
                                         int h, double ambient = 10) {
  std::vector<algo::Rgb8> image(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double acc[3] = {ambient, ambient, ambient};
      for (int sy = 0; sy < 4; ++sy) {
        for (int sx = 0; sx < 4; ++sx) {
          for (const auto& p : patterns) {
            const double s = stripeAt(p, w, h, x - 0.375 + sx * 0.25, y - 0.375 + sy * 0.25);
            const int k = static_cast<int>(std::floor(s));
            if (k >= 0 && k < algo::stripe::kStripes) {
              acc[algo::stripe::indexOf(algo::stripe::kSequence[static_cast<std::size_t>(k)])] +=
                  p.level / 16.0;
            }
          }
        }
      }
      const auto clip = [](double v) {
        return static_cast<std::uint8_t>(std::lround(v < 0 ? 0 : (v > 255 ? 255 : v)));
      };
      image[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
            static_cast<std::size_t>(x)] = {clip(acc[0]), clip(acc[1]), clip(acc[2])};
    }
  }
  return image;
}

// The image seen on a surface whose colour varies (a fade across x in red, across y in green),
// with Gaussian noise of σ 8 grey levels: the strength plateaus, contrast floors and colour
// divisors of the demultiplexer then take many values.
inline void colourAndNoise(std::vector<algo::Rgb8>& image, int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 8.0);
  const auto channel = [&](std::uint8_t v, double gain) {
    const double out = v * gain + noise(rng);
    return static_cast<std::uint8_t>(out < 0 ? 0 : (out > 255 ? 255 : out + 0.5));
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      algo::Rgb8& px = image[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                             static_cast<std::size_t>(x)];
      const double fade = 0.55 + 0.45 * x / w;
      px = {channel(px.r, fade), channel(px.g, 1.0 - 0.3 * y / h), channel(px.b, 0.8)};
    }
  }
}

}  // namespace smx::test
