#include "demux_debug.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "colour_map.hpp"
#include "output_files.hpp"

namespace smx::host {

namespace {

std::uint8_t clip(double v) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
}

}  // namespace

sim::RgbImage renderBoundaries(algo::ConstBoundaryPlane boundaries) {
  sim::RgbImage out = blankImage(boundaries.width(), boundaries.height());
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
  sim::RgbImage out = blankImage(w, h);
  // 32 × grey level per pixel: an edge of 50 grey levels per pixel shows as ±100.
  constexpr double kGain = 1.0 / 16.0;
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
  sim::RgbImage out = blankImage(w, h);
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
      out.pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                 static_cast<std::size_t>(x)] =
          hueColour(directions(x, y) / 65536.0, near ? 1.0 : 110.0 / 255.0);
    }
  }
  return out;
}

std::expected<void, std::string> writeDemuxDebug(OutputFolder& dir, const std::string& tag,
                                                 const algo::Demultiplexer& demux, int projector) {
  const algo::ImageView<const std::int16_t> separated[3] = {
      demux.separated(projector, 0), demux.separated(projector, 1), demux.separated(projector, 2)};
  const std::pair<const char*, sim::RgbImage> images[] = {
      {".boundaries.png", renderBoundaries(demux.boundaries(projector))},
      {".separated.png", renderSeparated(separated)},
      {".direction.png",
       renderDirections(demux.directions(projector), demux.boundaries(projector))},
  };
  for (const auto& [suffix, image] : images) {
    if (auto ok = writePngRgb8(dir, tag + suffix, image.view()); !ok) {
      return ok;
    }
  }
  return {};
}

}  // namespace smx::host
