#include "demux_debug.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace smx::host {

namespace {

sim::RgbImage blank(int width, int height) {
  return {
      width, height,
      std::vector<algo::Rgb8>(static_cast<std::size_t>(width) * static_cast<std::size_t>(height),
                              algo::Rgb8{0, 0, 0})};
}

std::uint8_t clip(double v) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
}

}  // namespace

sim::RgbImage renderBoundaries(algo::ConstBoundaryPlane boundaries) {
  sim::RgbImage out = blank(boundaries.width(), boundaries.height());
  for (int y = 0; y < boundaries.height(); ++y) {
    for (int x = 0; x < boundaries.width(); ++x) {
      const algo::Boundary b = boundaries(x, y);
      if (!b.present()) {
        continue;
      }
      const auto level = static_cast<std::uint8_t>(96 + (159 * b.confidence) / 255);
      algo::Rgb8 colour{0, 0, 0};
      switch (algo::stripe::colourAfter(b.kind())) {
        case algo::stripe::Colour::kRed:
          colour.r = level;
          break;
        case algo::stripe::Colour::kGreen:
          colour.g = level;
          break;
        case algo::stripe::Colour::kBlue:
          colour.b = level;
          break;
      }
      out.pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) +
                 static_cast<std::size_t>(x)] = colour;
    }
  }
  return out;
}

sim::RgbImage renderSeparated(const algo::ImageView<const std::int16_t> (&channels)[3]) {
  const int w = channels[0].width();
  const int h = channels[0].height();
  sim::RgbImage out = blank(w, h);
  // Q4.11: ±1 (a step of the local average colour per pixel) spans ±127 grey levels.
  constexpr double kGain = 127.0 / 2048.0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      out.pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                 static_cast<std::size_t>(x)] = {clip(128 + kGain * channels[0](x, y)),
                                                 clip(128 + kGain * channels[1](x, y)),
                                                 clip(128 + kGain * channels[2](x, y))};
    }
  }
  return out;
}

sim::RgbImage renderDirections(algo::ConstDirectionPlane directions,
                               algo::ConstBoundaryPlane boundaries) {
  const int w = directions.width();
  const int h = directions.height();
  sim::RgbImage out = blank(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      bool near = false;
      for (int dy = -1; dy <= 1 && !near; ++dy) {
        for (int dx = -1; dx <= 1 && !near; ++dx) {
          const int nx = std::clamp(x + dx, 0, w - 1);
          const int ny = std::clamp(y + dy, 0, h - 1);
          near = boundaries(nx, ny).present();
        }
      }
      const double hue = directions(x, y) * (6.0 / 65536.0);  // sextants of the colour wheel
      const double f = hue - std::floor(hue);
      const double value = near ? 255.0 : 110.0;
      const double rising = value * f;
      const double falling = value * (1.0 - f);
      double r = 0;
      double g = 0;
      double b = 0;
      switch (static_cast<int>(hue)) {
        case 0:
          r = value;
          g = rising;
          break;
        case 1:
          r = falling;
          g = value;
          break;
        case 2:
          g = value;
          b = rising;
          break;
        case 3:
          g = falling;
          b = value;
          break;
        case 4:
          r = rising;
          b = value;
          break;
        default:
          r = value;
          b = falling;
          break;
      }
      out.pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                 static_cast<std::size_t>(x)] = {clip(r), clip(g), clip(b)};
    }
  }
  return out;
}

}  // namespace smx::host
