#pragma once

#include <cstddef>
#include <expected>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/sim/png_io.hpp"

// Charts as PNG files for the evaluation report (`stripemux eval`, docs/results.md): a depth error
// map, grouped bars and line/scatter charts. Each chart has a render* function returning the
// pixels (what the tests look at) and a write* wrapper that saves them. White background, one
// colour-blind-safe palette (Okabe-Ito) for bars and lines. Text is drawn with OpenCV's Hershey
// font, which has ASCII glyphs only. Errors are messages naming the problem (and the file).
namespace smx::plots {

// A rectangle of pixels: columns [x, x + width), rows [y, y + height).
struct PixelRect {
  int x = 0;
  int y = 0;
  int width = 0;
  int height = 0;
};

// A rendered chart and where its data went. For the axis charts a value range [lo, hi] maps
// linearly onto pixel centres: x = lo at column plot.x, x = hi at column plot.x + plot.width - 1;
// y = lo at the bottom row plot.y + plot.height - 1, y = hi at row plot.y. The axis lines lie
// just outside (column plot.x - 1, row plot.y + plot.height). For the error map, plot is the
// input image, copied 1:1.
struct Chart {
  sim::RgbImage image;
  PixelRect plot;
};

// Series i of a bar or line chart is drawn in seriesColour(i); the palette has seven colours
// and repeats after that.
[[nodiscard]] algo::Rgb8 seriesColour(std::size_t index);

// 1) Signed depth error in mm per pixel (row-major, width*height; NaN = no data, e.g. outside
// the object), diverging from blue (-rangeMm) through white (0) to red (+rangeMm), clipped
// beyond; no data is dark grey. A colour bar with ticks in mm on the right, the title above.
// The image is not scaled so that it lines up with the camera image, and it always starts at the
// same offset (kErrorMapLeftPx, kErrorMapTopPx) whatever its size.
inline constexpr int kErrorMapLeftPx = 16;
inline constexpr int kErrorMapTopPx = 60;

[[nodiscard]] std::expected<Chart, std::string> renderErrorMap(std::span<const float> errorsMm,
                                                               int width, int height,
                                                               double rangeMm,
                                                               const std::string& title);
[[nodiscard]] std::expected<void, std::string> writeErrorMap(const std::filesystem::path& png,
                                                             std::span<const float> errorsMm,
                                                             int width, int height, double rangeMm,
                                                             const std::string& title);

// 2) Grouped bars: one group per category along x (e.g. scenes), one bar per series in each
// group (e.g. "all lit", "lit by 2"). Bars rise from 0, or from the nearer end of [yMin, yMax]
// when 0 is outside it, and are clipped to the range. NaN = missing: no bar, "n/a" where it
// would be. Long category names are shrunk, then turned vertical, so they stay readable.
struct BarChart {
  std::string title;
  std::string yLabel;
  double yMin = 0;
  double yMax = 1;
  std::vector<std::string> categories;
  std::vector<std::string> series;
  std::vector<std::vector<double>> values;  // [series][category]
};

[[nodiscard]] std::expected<Chart, std::string> renderBarChart(const BarChart& chart);
[[nodiscard]] std::expected<void, std::string> writeBarChart(const std::filesystem::path& png,
                                                             const BarChart& chart);

// 3) Series of (x, y) points as markers joined by lines, or, with linesJoined false, as small
// dots (scatter of many points). A non-finite point leaves a gap. Ranges not given are the
// data's with a 5% margin; points outside a given range are clipped.
struct Series {
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
};

struct LineChart {
  std::string title;
  std::string xLabel;
  std::string yLabel;
  std::vector<Series> series;
  bool linesJoined = true;
  std::optional<std::pair<double, double>> xRange;  // (lo, hi)
  std::optional<std::pair<double, double>> yRange;
};

[[nodiscard]] std::expected<Chart, std::string> renderLineChart(const LineChart& chart);
[[nodiscard]] std::expected<void, std::string> writeLineChart(const std::filesystem::path& png,
                                                              const LineChart& chart);

// The size of the bar and line charts.
inline constexpr int kChartWidth = 800;
inline constexpr int kChartHeight = 500;

}  // namespace smx::plots
