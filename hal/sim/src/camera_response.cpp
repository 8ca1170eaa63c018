#include "camera_response.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace smx::sim::detail {

Vignetting::Vignetting(const algo::Camera& camera, double v)
    : v_(v), cx_(camera.K[2]), cy_(camera.K[5]) {
  double corner2 = 0.0;
  for (const double x : {-0.5, camera.width - 0.5}) {
    for (const double y : {-0.5, camera.height - 0.5}) {
      corner2 = std::max(corner2, (x - cx_) * (x - cx_) + (y - cy_) * (y - cy_));
    }
  }
  inverseCorner2_ = corner2 > 0.0 ? 1.0 / corner2 : 0.0;
}

double Vignetting::gain(int x, int y) const {
  const double dx = x - cx_;
  const double dy = y - cy_;
  return 1.0 - v_ * (dx * dx + dy * dy) * inverseCorner2_;
}

void applyResponseGamma(std::vector<RgbF>& linear, double gamma) {
  if (gamma == 1.0) {
    return;
  }
  const double exponent = 1.0 / gamma;
  for (RgbF& px : linear) {
    for (float& c : px) {
      c = c > 0.0F ? static_cast<float>(255.0 * std::pow(c / 255.0, exponent)) : 0.0F;
    }
  }
}

std::optional<BayerCell> bayerCell(std::string_view pattern) {
  if (pattern.size() != 4) {
    return std::nullopt;
  }
  BayerCell cell;
  for (std::size_t i = 0; i < 4; ++i) {
    switch (pattern[i]) {
      case 'r':
        cell.channel[i] = 0;
        break;
      case 'g':
        cell.channel[i] = 1;
        break;
      case 'b':
        cell.channel[i] = 2;
        break;
      default:
        return std::nullopt;
    }
  }
  return cell;
}

void mosaicAndDemosaic(algo::RgbView image, const BayerCell& cell) {
  const int width = image.width();
  const int height = image.height();
  const auto index = [width](int x, int y) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(x);
  };
  const auto channel = [](const algo::Rgb8& p, std::size_t c) {
    return c == 0 ? p.r : (c == 1 ? p.g : p.b);
  };
  std::vector<std::uint8_t> raw(index(0, height));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      raw[index(x, y)] = channel(image(x, y), cell.at(x, y));
    }
  }
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      std::array<unsigned, 3> sum{};
      std::array<unsigned, 3> count{};
      for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, height - 1); ++ny) {
        for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, width - 1); ++nx) {
          const std::size_t c = cell.at(nx, ny);
          sum[c] += raw[index(nx, ny)];
          ++count[c];
        }
      }
      // The pixel's own channel is its own value; the others are their neighbours' mean (the
      // centre never adds to them: it kept another channel).
      const std::size_t own = cell.at(x, y);
      std::array<std::uint8_t, 3> out{};
      for (std::size_t c = 0; c < 3; ++c) {
        out[c] = c == own ? raw[index(x, y)]
                          : static_cast<std::uint8_t>(
                                count[c] == 0 ? 0U : (sum[c] + count[c] / 2U) / count[c]);
      }
      image(x, y) = algo::Rgb8{out[0], out[1], out[2]};
    }
  }
}

}  // namespace smx::sim::detail
