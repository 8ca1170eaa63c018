#include "smx/plots/plots.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace smx::plots {
namespace {

// The canvas is CV_8UC3 with channels in RGB order, so it copies straight into an RgbImage;
// every colour below is (r, g, b).
constexpr algo::Rgb8 kBackground{255, 255, 255};
constexpr algo::Rgb8 kTextColour{40, 40, 40};
constexpr algo::Rgb8 kAxisColour{90, 90, 90};
constexpr algo::Rgb8 kGridColour{228, 228, 228};
constexpr algo::Rgb8 kMutedColour{150, 150, 150};
constexpr algo::Rgb8 kFrameColour{180, 180, 180};
constexpr algo::Rgb8 kNoDataColour{80, 80, 80};

// Okabe & Ito, "Color Universal Design" (2008), without black (the axes' colour); yellow last
// since it is faint on white.
constexpr std::array<algo::Rgb8, 7> kPalette{{
    {0, 114, 178},    // blue
    {230, 159, 0},    // orange
    {0, 158, 115},    // bluish green
    {213, 94, 0},     // vermillion
    {86, 180, 233},   // sky blue
    {204, 121, 167},  // reddish purple
    {240, 228, 66},   // yellow
}};

// ColorBrewer RdBu (Brewer 2002) from blue to red with a pure white middle, so zero error reads
// as "nothing there"; the darkest ends are left out so they stay apart from the no-data grey.
constexpr std::array<algo::Rgb8, 9> kDiverging{{
    {33, 102, 172},
    {67, 147, 195},
    {146, 197, 222},
    {209, 229, 240},
    {255, 255, 255},
    {253, 219, 199},
    {244, 165, 130},
    {214, 96, 77},
    {178, 24, 43},
}};

cv::Scalar scalar(algo::Rgb8 c) {
  return {static_cast<double>(c.r), static_cast<double>(c.g), static_cast<double>(c.b)};
}

// t in [-1, 1] (clipped) onto the diverging scale.
algo::Rgb8 diverging(double t) {
  const double u = (std::clamp(t, -1.0, 1.0) + 1.0) * 0.5 * (kDiverging.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(u), kDiverging.size() - 2);
  const double f = u - static_cast<double>(i);
  const auto mix = [f](std::uint8_t a, std::uint8_t b) {
    return static_cast<std::uint8_t>(std::lround(a + f * (b - a)));
  };
  const algo::Rgb8 a = kDiverging[i];
  const algo::Rgb8 b = kDiverging[i + 1];
  return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

// ---- Text (Hershey, ASCII only) ----

struct Font {
  int face;
  double scale;
  int thickness;
};
constexpr Font kTitleFont{cv::FONT_HERSHEY_DUPLEX, 0.7, 1};
constexpr Font kLabelFont{cv::FONT_HERSHEY_SIMPLEX, 0.5, 1};
constexpr Font kTickFont{cv::FONT_HERSHEY_SIMPLEX, 0.42, 1};
constexpr Font kNoteFont{cv::FONT_HERSHEY_SIMPLEX, 0.35, 1};

enum class Align { kLeft, kCentre, kRight };

struct TextSize {
  int width;
  int ascent;   // above the baseline
  int descent;  // below it
};

TextSize measure(const std::string& text, const Font& font) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, font.face, font.scale, font.thickness, &baseline);
  return {size.width, size.height, baseline};
}

// The text cut to maxWidth, ending in ".." when cut; a reader still sees what it was.
std::string fitText(const std::string& text, const Font& font, int maxWidth) {
  if (measure(text, font).width <= maxWidth) {
    return text;
  }
  std::string cut = text;
  while (!cut.empty() && measure(cut + "..", font).width > maxWidth) {
    cut.pop_back();
  }
  return cut.empty() ? std::string{} : cut + "..";
}

// Text whose capitals are centred vertically on yMiddle, aligned horizontally at x.
void drawText(cv::Mat& canvas, const std::string& text, int x, int yMiddle, Align align,
              const Font& font, algo::Rgb8 colour) {
  const TextSize size = measure(text, font);
  int left = x;
  if (align == Align::kCentre) {
    left = x - size.width / 2;
  } else if (align == Align::kRight) {
    left = x - size.width;
  }
  cv::putText(canvas, text, {left, yMiddle + size.ascent / 2}, font.face, font.scale,
              scalar(colour), font.thickness, cv::LINE_AA);
}

// Text turned to read upwards, centred on column xMiddle, its top edge (the text's end) at yTop.
// Hershey text cannot be rotated, so it is drawn on a strip that is turned; dark text on a light
// background keeps the darker pixel of strip and canvas.
void drawTextUp(cv::Mat& canvas, const std::string& text, int xMiddle, int yTop, const Font& font,
                algo::Rgb8 colour) {
  const TextSize size = measure(text, font);
  cv::Mat strip(size.ascent + size.descent + 2, size.width + 2, CV_8UC3, scalar(kBackground));
  cv::putText(strip, text, {1, size.ascent + 1}, font.face, font.scale, scalar(colour),
              font.thickness, cv::LINE_AA);
  cv::Mat up;
  cv::rotate(strip, up, cv::ROTATE_90_COUNTERCLOCKWISE);
  // The glyphs' vertical middle (capitals) becomes the column to centre on.
  const int left = xMiddle - (size.ascent + 1) / 2 - 1;
  const cv::Rect wanted(left, yTop, up.cols, up.rows);
  const cv::Rect where = wanted & cv::Rect(0, 0, canvas.cols, canvas.rows);
  if (where.empty()) {
    return;
  }
  cv::Mat target = canvas(where);
  cv::min(target, up(where - wanted.tl()), target);
}

// A value with a fixed number of decimals, never "-0".
std::string formatNumber(double value, int decimals) {
  if (std::abs(value) < 0.5 * std::pow(10.0, -decimals)) {
    value = 0.0;
  }
  std::array<char, 64> buffer{};
  const bool huge = std::abs(value) >= 1e9;
  const auto [end, ec] = huge ? std::to_chars(buffer.data(), buffer.data() + buffer.size(), value,
                                              std::chars_format::general, 3)
                              : std::to_chars(buffer.data(), buffer.data() + buffer.size(), value,
                                              std::chars_format::fixed, decimals);
  if (ec != std::errc{}) {
    return "?";
  }
  return {buffer.data(), end};
}

// ---- Axes ----

// Tick values at 1, 2 or 5 times a power of ten, and the decimals that show them exactly.
struct Ticks {
  std::vector<double> values;
  int decimals = 0;
};

Ticks niceTicks(double lo, double hi, int target) {
  const double raw = (hi - lo) / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / magnitude;
  const double step = (f < 1.5 ? 1.0 : f < 3.0 ? 2.0 : f < 7.0 ? 5.0 : 10.0) * magnitude;
  Ticks ticks;
  ticks.decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  const double first = std::ceil(lo / step - 1e-9);
  const double last = std::floor(hi / step + 1e-9);
  for (double k = first; k <= last && ticks.values.size() < 100; k += 1.0) {
    ticks.values.push_back(k * step);
  }
  return ticks;
}

// A value range onto pixel centres (see Chart in the header).
struct Axis {
  double lo;
  double hi;
  double loPx;
  double hiPx;
  [[nodiscard]] double toPx(double v) const { return loPx + (v - lo) / (hi - lo) * (hiPx - loPx); }
};

Axis xAxisOf(const PixelRect& plot, double lo, double hi) {
  return {lo, hi, static_cast<double>(plot.x), static_cast<double>(plot.x + plot.width - 1)};
}

Axis yAxisOf(const PixelRect& plot, double lo, double hi) {
  return {lo, hi, static_cast<double>(plot.y + plot.height - 1), static_cast<double>(plot.y)};
}

int px(double v) {
  return static_cast<int>(std::lround(v));
}

enum class Swatch { kBox, kLineAndMarker, kDot };

constexpr int kTitleBandPx = 40;
constexpr int kLegendRowPx = 20;
constexpr int kRightMarginPx = 28;
constexpr int kTickLengthPx = 5;

void drawTitle(cv::Mat& canvas, const std::string& title) {
  if (title.empty()) {
    return;
  }
  Font font = kTitleFont;
  const int room = canvas.cols - 24;
  const int width = measure(title, font).width;
  if (width > room) {
    font.scale = std::max(0.45, font.scale * room / width);
  }
  drawText(canvas, fitText(title, font, room), canvas.cols / 2, 20, Align::kCentre, font,
           kTextColour);
}

void drawSwatch(cv::Mat& canvas, Swatch swatch, int x, int yMiddle, algo::Rgb8 colour) {
  switch (swatch) {
    case Swatch::kBox:
      cv::rectangle(canvas, cv::Rect(x, yMiddle - 6, 12, 12), scalar(colour), cv::FILLED);
      break;
    case Swatch::kLineAndMarker:
      cv::line(canvas, {x, yMiddle}, {x + 22, yMiddle}, scalar(colour), 2, cv::LINE_AA);
      cv::circle(canvas, {x + 11, yMiddle}, 4, scalar(colour), cv::FILLED, cv::LINE_AA);
      break;
    case Swatch::kDot:
      cv::circle(canvas, {x + 5, yMiddle}, 3, scalar(colour), cv::FILLED, cv::LINE_AA);
      break;
  }
}

// The legend in centred rows under the title; returns the row below it. Nothing when every
// label is empty (a single unnamed series needs no legend).
int drawLegend(cv::Mat& canvas, const std::vector<std::string>& labels, Swatch swatch, int top) {
  if (std::all_of(labels.begin(), labels.end(), [](const auto& l) { return l.empty(); })) {
    return top;
  }
  const int swatchPx = swatch == Swatch::kBox ? 12 : swatch == Swatch::kDot ? 10 : 22;
  constexpr int kGapPx = 6;
  constexpr int kSpacingPx = 22;
  const int room = canvas.cols - 40;
  struct Item {
    std::string text;
    int width;
    algo::Rgb8 colour;
  };
  std::vector<std::vector<Item>> rows(1);
  int rowWidth = 0;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    std::string text = fitText(labels[i], kLabelFont, room - swatchPx - kGapPx);
    const int width = swatchPx + kGapPx + measure(text, kLabelFont).width;
    if (!rows.back().empty() && rowWidth + kSpacingPx + width > room) {
      rows.emplace_back();
      rowWidth = 0;
    }
    rowWidth += (rows.back().empty() ? 0 : kSpacingPx) + width;
    rows.back().push_back({std::move(text), width, seriesColour(i)});
  }
  int y = top + kLegendRowPx / 2;
  for (const auto& row : rows) {
    int total = 0;
    for (const auto& item : row) {
      total += item.width;
    }
    total += kSpacingPx * static_cast<int>(row.size() - 1);
    int x = (canvas.cols - total) / 2;
    for (const auto& item : row) {
      drawSwatch(canvas, swatch, x, y, item.colour);
      drawText(canvas, item.text, x + swatchPx + kGapPx, y, Align::kLeft, kLabelFont, kTextColour);
      x += item.width + kSpacingPx;
    }
    y += kLegendRowPx;
  }
  return top + kLegendRowPx * static_cast<int>(rows.size());
}

struct AxisChartSetup {
  std::string title;
  std::vector<std::string> legend;
  Swatch swatch;
  std::string yLabel;
  double yLo;
  double yHi;
  int bottomPx;  // room below the plot for the x axis' labels
};

// A canvas with title, legend and the y axis (grid, ticks, label) of a bar or line chart.
Chart startAxisChart(cv::Mat& canvas, const AxisChartSetup& setup) {
  canvas.create(kChartHeight, kChartWidth, CV_8UC3);
  canvas.setTo(scalar(kBackground));
  drawTitle(canvas, setup.title);
  const int legendTop = setup.title.empty() ? 10 : kTitleBandPx;
  const int top = drawLegend(canvas, setup.legend, setup.swatch, legendTop) + 14;

  const Ticks ticks = niceTicks(setup.yLo, setup.yHi, 6);
  int tickLabelPx = 0;
  for (const double v : ticks.values) {
    tickLabelPx = std::max(tickLabelPx, measure(formatNumber(v, ticks.decimals), kTickFont).width);
  }
  const int labelBandPx = setup.yLabel.empty() ? 10 : 34;
  const int left = labelBandPx + tickLabelPx + kTickLengthPx + 6;
  Chart chart;
  chart.plot = {left, top, kChartWidth - left - kRightMarginPx,
                kChartHeight - top - setup.bottomPx};
  const PixelRect& plot = chart.plot;
  const Axis y = yAxisOf(plot, setup.yLo, setup.yHi);
  for (const double v : ticks.values) {
    const int row = px(y.toPx(v));
    cv::line(canvas, {plot.x, row}, {plot.x + plot.width - 1, row}, scalar(kGridColour));
    cv::line(canvas, {plot.x - 1 - kTickLengthPx, row}, {plot.x - 2, row}, scalar(kAxisColour));
    drawText(canvas, formatNumber(v, ticks.decimals), plot.x - kTickLengthPx - 5, row,
             Align::kRight, kTickFont, kTextColour);
  }
  if (!setup.yLabel.empty()) {
    const std::string text = fitText(setup.yLabel, kLabelFont, plot.height);
    const int width = measure(text, kLabelFont).width;
    drawTextUp(canvas, text, 14, plot.y + (plot.height - width) / 2, kLabelFont, kTextColour);
  }
  return chart;
}

// The left and bottom axis lines, drawn last so that nothing covers them.
void drawAxisLines(cv::Mat& canvas, const PixelRect& plot) {
  const int bottom = plot.y + plot.height;
  cv::line(canvas, {plot.x - 1, plot.y}, {plot.x - 1, bottom}, scalar(kAxisColour));
  cv::line(canvas, {plot.x - 1, bottom}, {plot.x + plot.width - 1, bottom}, scalar(kAxisColour));
}

sim::RgbImage toRgbImage(const cv::Mat& canvas) {
  sim::RgbImage image{canvas.cols, canvas.rows,
                      std::vector<algo::Rgb8>(static_cast<std::size_t>(canvas.cols) *
                                              static_cast<std::size_t>(canvas.rows))};
  const auto rowBytes = static_cast<std::size_t>(canvas.cols) * sizeof(algo::Rgb8);
  for (int y = 0; y < canvas.rows; ++y) {
    std::memcpy(
        image.pixels.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(canvas.cols),
        canvas.ptr<std::uint8_t>(y), rowBytes);
  }
  return image;
}

// OpenCV reports bad arguments and allocation failures by throwing; none of that leaves here.
template <class Render>
auto guarded(const char* what, Render&& render) -> decltype(render()) {
  try {
    return std::forward<Render>(render)();
  } catch (const std::exception& e) {
    return std::unexpected(std::string(what) + ": " + e.what());
  }
}

bool finite(double v) {
  return std::isfinite(v);
}

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

// ---- The charts ----

// The fewest decimals (up to 3) that show both v and v/2 exactly.
int decimalsFor(double v) {
  for (int d = 0; d < 3; ++d) {
    const double scale = std::pow(10.0, d);
    if (std::abs(std::round(v * scale) - v * scale) < 1e-6 &&
        std::abs(std::round(v * scale / 2) - v * scale / 2) < 1e-6) {
      return d;
    }
  }
  return 3;
}

std::expected<Chart, std::string> errorMap(std::span<const float> errorsMm, int width, int height,
                                           double rangeMm, const std::string& title) {
  if (width <= 0 || height <= 0) {
    return std::unexpected("error map: size " + std::to_string(width) + "x" +
                           std::to_string(height) + " is not positive");
  }
  if (errorsMm.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    return std::unexpected("error map: " + std::to_string(errorsMm.size()) + " errors for a " +
                           std::to_string(width) + "x" + std::to_string(height) +
                           " image (width*height expected)");
  }
  if (!finite(rangeMm) || rangeMm <= 0) {
    return std::unexpected("error map: range must be positive and finite (got " +
                           formatNumber(rangeMm, 3) + " mm)");
  }
  constexpr int kGapPx = 18;
  constexpr int kBarWidthPx = 18;
  constexpr int kMinBarHeightPx = 180;
  const int decimals = decimalsFor(rangeMm);
  const std::array<double, 5> tickValues{rangeMm, rangeMm / 2, 0.0, -rangeMm / 2, -rangeMm};
  const auto tickLabel = [decimals](double v) {
    return v == 0.0 ? std::string("0") : (v > 0 ? "+" : "") + formatNumber(v, decimals);
  };
  int tickLabelPx = measure("mm", kLabelFont).width;
  for (const double v : tickValues) {
    tickLabelPx = std::max(tickLabelPx, measure(tickLabel(v), kTickFont).width);
  }
  const int barX = kErrorMapLeftPx + width + kGapPx;
  const int barHeight = std::max(height, kMinBarHeightPx);
  const int canvasWidth = std::max(barX + kBarWidthPx + kTickLengthPx + 6 + tickLabelPx + 16,
                                   std::min(measure(title, kTitleFont).width + 32, 2000));
  const int canvasHeight = kErrorMapTopPx + std::max(height, barHeight + 34) + 14;

  cv::Mat canvas(canvasHeight, canvasWidth, CV_8UC3, scalar(kBackground));
  drawTitle(canvas, title);

  Chart chart;
  chart.plot = {kErrorMapLeftPx, kErrorMapTopPx, width, height};
  cv::rectangle(canvas, cv::Rect(kErrorMapLeftPx - 1, kErrorMapTopPx - 1, width + 2, height + 2),
                scalar(kFrameColour));
  for (int y = 0; y < height; ++y) {
    auto* row = canvas.ptr<algo::Rgb8>(kErrorMapTopPx + y) + kErrorMapLeftPx;
    for (int x = 0; x < width; ++x) {
      const float e = errorsMm[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                               static_cast<std::size_t>(x)];
      row[x] = std::isnan(e) ? kNoDataColour : diverging(e / rangeMm);
    }
  }

  // The colour bar: +range at the top row, -range at the bottom.
  const Axis bar{-rangeMm, rangeMm, static_cast<double>(kErrorMapTopPx + barHeight - 1),
                 static_cast<double>(kErrorMapTopPx)};
  for (int y = 0; y < barHeight; ++y) {
    const double t = (bar.loPx - (kErrorMapTopPx + y)) / (bar.loPx - bar.hiPx);  // 0 bottom, 1 top
    const double v = bar.lo + t * (bar.hi - bar.lo);
    cv::line(canvas, {barX, kErrorMapTopPx + y}, {barX + kBarWidthPx - 1, kErrorMapTopPx + y},
             scalar(diverging(v / rangeMm)));
  }
  cv::rectangle(canvas, cv::Rect(barX - 1, kErrorMapTopPx - 1, kBarWidthPx + 2, barHeight + 2),
                scalar(kAxisColour));
  const int tickX = barX + kBarWidthPx;
  for (const double v : tickValues) {
    const int row = px(bar.toPx(v));
    cv::line(canvas, {tickX, row}, {tickX + kTickLengthPx - 1, row}, scalar(kAxisColour));
    drawText(canvas, tickLabel(v), tickX + kTickLengthPx + 4, row, Align::kLeft, kTickFont,
             kTextColour);
  }
  drawText(canvas, "mm", barX + kBarWidthPx / 2, kErrorMapTopPx - 14, Align::kCentre, kLabelFont,
           kTextColour);
  // What the grey means, under the bar.
  const int keyY = kErrorMapTopPx + barHeight + 18;
  cv::rectangle(canvas, cv::Rect(barX, keyY - 6, 12, 12), scalar(kNoDataColour), cv::FILLED);
  drawText(canvas, "no data", barX + 17, keyY, Align::kLeft, kTickFont, kTextColour);

  chart.image = toRgbImage(canvas);
  return chart;
}

std::expected<void, std::string> checkBarChart(const BarChart& chart) {
  if (chart.categories.empty()) {
    return std::unexpected("bar chart: no categories");
  }
  if (chart.series.empty()) {
    return std::unexpected("bar chart: no series");
  }
  if (!finite(chart.yMin) || !finite(chart.yMax) || chart.yMax <= chart.yMin) {
    return std::unexpected("bar chart: y range [" + formatNumber(chart.yMin, 3) + ", " +
                           formatNumber(chart.yMax, 3) +
                           "] is empty (yMax must be greater than yMin)");
  }
  if (chart.values.size() != chart.series.size()) {
    return std::unexpected("bar chart: values has " + std::to_string(chart.values.size()) +
                           " rows for " + std::to_string(chart.series.size()) + " series");
  }
  for (std::size_t s = 0; s < chart.series.size(); ++s) {
    if (chart.values[s].size() != chart.categories.size()) {
      return std::unexpected("bar chart: series " + quoted(chart.series[s]) + " has " +
                             std::to_string(chart.values[s].size()) + " values for " +
                             std::to_string(chart.categories.size()) + " categories");
    }
  }
  return {};
}

// How the category names fit under their groups.
struct CategoryLabels {
  std::vector<std::string> texts;
  Font font = kLabelFont;
  bool upright = false;  // read upwards, one under each group
  int bandPx = 0;        // room they take below the plot
};

CategoryLabels layoutCategories(const std::vector<std::string>& categories, double groupPx) {
  constexpr double kMinScale = 0.36;
  constexpr int kMaxUprightPx = 170;
  CategoryLabels labels;
  int widest = 0;
  for (const auto& c : categories) {
    widest = std::max(widest, measure(c, kLabelFont).width);
  }
  const double room = groupPx - 8;
  if (widest <= room || kLabelFont.scale * room / widest >= kMinScale) {
    if (widest > room) {
      labels.font.scale = kLabelFont.scale * room / widest;
    }
    labels.texts = categories;
    labels.bandPx = 34;
    return labels;
  }
  labels.font = kTickFont;
  labels.upright = true;
  int tallest = 0;
  for (const auto& c : categories) {
    labels.texts.push_back(fitText(c, labels.font, kMaxUprightPx));
    tallest = std::max(tallest, measure(labels.texts.back(), labels.font).width);
  }
  labels.bandPx = tallest + 18;
  return labels;
}

std::expected<Chart, std::string> barChart(const BarChart& input) {
  if (auto ok = checkBarChart(input); !ok) {
    return std::unexpected(ok.error());
  }
  const std::size_t categories = input.categories.size();
  const std::size_t series = input.series.size();
  // The plot's width is known only after the y axis' labels are measured; the category labels
  // are laid out for a close estimate of it.
  const double estimatePx = (kChartWidth - 110.0) / static_cast<double>(categories);
  const CategoryLabels labels = layoutCategories(input.categories, estimatePx);

  cv::Mat canvas;
  Chart chart = startAxisChart(canvas, {input.title, input.series, Swatch::kBox, input.yLabel,
                                        input.yMin, input.yMax, labels.bandPx});
  const PixelRect& plot = chart.plot;
  const Axis y = yAxisOf(plot, input.yMin, input.yMax);
  const double base = std::clamp(0.0, input.yMin, input.yMax);
  const double groupPx = static_cast<double>(plot.width) / static_cast<double>(categories);
  const double padPx = 0.15 * groupPx;
  const double barPx = (groupPx - 2 * padPx) / static_cast<double>(series);
  const int gapPx = series > 1 && barPx >= 6 ? 1 : 0;

  for (std::size_t c = 0; c < categories; ++c) {
    const double groupX = plot.x + static_cast<double>(c) * groupPx;
    for (std::size_t s = 0; s < series; ++s) {
      const int x0 = px(groupX + padPx + static_cast<double>(s) * barPx);
      const int x1 =
          std::max(x0, px(groupX + padPx + static_cast<double>(s + 1) * barPx) - 1 - gapPx);
      const double v = input.values[s][c];
      if (std::isnan(v)) {
        const std::string na = "n/a";
        const TextSize size = measure(na, kNoteFont);
        const int centre = (x0 + x1) / 2;
        const int baseRow = px(y.toPx(base));
        if (size.width <= x1 - x0 + 5) {
          drawText(canvas, na, centre, baseRow - 8, Align::kCentre, kNoteFont, kMutedColour);
        } else if (size.ascent <= x1 - x0 + 5) {
          drawTextUp(canvas, na, centre, baseRow - 3 - size.width, kNoteFont, kMutedColour);
        }
        continue;
      }
      const double rowV = y.toPx(std::clamp(v, input.yMin, input.yMax));
      const double rowBase = y.toPx(base);
      const int top = px(std::min(rowV, rowBase));
      const int bottom = px(std::max(rowV, rowBase));
      cv::rectangle(canvas, cv::Point(x0, top), cv::Point(x1, bottom), scalar(seriesColour(s)),
                    cv::FILLED);
    }
    const int centre = px(groupX + groupPx / 2);
    const int below = plot.y + plot.height + 1;
    if (labels.upright) {
      drawTextUp(canvas, labels.texts[c], centre, below + 8, labels.font, kTextColour);
    } else {
      drawText(canvas, labels.texts[c], centre, below + 14, Align::kCentre, labels.font,
               kTextColour);
    }
  }
  if (base > input.yMin) {
    const int row = px(y.toPx(base));
    cv::line(canvas, {plot.x, row}, {plot.x + plot.width - 1, row}, scalar(kAxisColour));
  }
  drawAxisLines(canvas, plot);
  chart.image = toRgbImage(canvas);
  return chart;
}

// The range of one coordinate: given, or the finite points' with a margin.
std::expected<std::pair<double, double>, std::string> rangeOf(
    const LineChart& chart, const std::optional<std::pair<double, double>>& given, bool xs) {
  const char* name = xs ? "x" : "y";
  if (given) {
    const auto [lo, hi] = *given;
    if (!finite(lo) || !finite(hi) || hi <= lo) {
      return std::unexpected(std::string("line chart: ") + name + " range (" + formatNumber(lo, 3) +
                             ", " + formatNumber(hi, 3) +
                             ") is empty (hi must be greater than lo)");
    }
    return *given;
  }
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const auto& s : chart.series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (finite(s.x[i]) && finite(s.y[i])) {
        const double v = xs ? s.x[i] : s.y[i];
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    }
  }
  if (lo > hi) {
    return std::unexpected(std::string("line chart: no finite points to set the ") + name +
                           " range from");
  }
  const double margin = hi > lo ? 0.05 * (hi - lo) : (lo == 0 ? 1.0 : 0.1 * std::abs(lo));
  return std::pair{lo - margin, hi + margin};
}

std::expected<Chart, std::string> lineChart(const LineChart& input) {
  if (input.series.empty()) {
    return std::unexpected("line chart: no series");
  }
  for (const auto& s : input.series) {
    if (s.x.size() != s.y.size()) {
      return std::unexpected("line chart: series " + quoted(s.label) + " has " +
                             std::to_string(s.x.size()) + " x values but " +
                             std::to_string(s.y.size()) + " y values");
    }
  }
  const auto xRange = rangeOf(input, input.xRange, true);
  if (!xRange) {
    return std::unexpected(xRange.error());
  }
  const auto yRange = rangeOf(input, input.yRange, false);
  if (!yRange) {
    return std::unexpected(yRange.error());
  }
  std::vector<std::string> legend;
  legend.reserve(input.series.size());
  for (const auto& s : input.series) {
    legend.push_back(s.label);
  }
  const int bottomPx = input.xLabel.empty() ? 30 : 54;
  cv::Mat canvas;
  Chart chart = startAxisChart(
      canvas, {input.title, legend, input.linesJoined ? Swatch::kLineAndMarker : Swatch::kDot,
               input.yLabel, yRange->first, yRange->second, bottomPx});
  const PixelRect& plot = chart.plot;
  const Axis x = xAxisOf(plot, xRange->first, xRange->second);
  const Axis y = yAxisOf(plot, yRange->first, yRange->second);

  const Ticks xTicks = niceTicks(x.lo, x.hi, 8);
  const int bottom = plot.y + plot.height;
  for (const double v : xTicks.values) {
    const int column = px(x.toPx(v));
    cv::line(canvas, {column, plot.y}, {column, bottom - 1}, scalar(kGridColour));
    cv::line(canvas, {column, bottom + 1}, {column, bottom + kTickLengthPx}, scalar(kAxisColour));
    drawText(canvas, formatNumber(v, xTicks.decimals), column, bottom + kTickLengthPx + 11,
             Align::kCentre, kTickFont, kTextColour);
  }
  if (!input.xLabel.empty()) {
    drawText(canvas, fitText(input.xLabel, kLabelFont, plot.width), plot.x + plot.width / 2,
             bottom + 40, Align::kCentre, kLabelFont, kTextColour);
  }

  // Lines are clipped to the plot by drawing into it; markers only where the point is inside,
  // drawn whole.
  constexpr int kShift = 4;  // sub-pixel positions, 1/16 px
  const auto fixed = [](double v) { return px(v * (1 << kShift)); };
  cv::Mat area = canvas(cv::Rect(plot.x, plot.y, plot.width, plot.height));
  const auto inside = [&](double vx, double vy) {
    return vx >= x.lo && vx <= x.hi && vy >= y.lo && vy <= y.hi;
  };
  for (std::size_t s = 0; s < input.series.size(); ++s) {
    const Series& series = input.series[s];
    const cv::Scalar colour = scalar(seriesColour(s));
    if (input.linesJoined) {
      for (std::size_t i = 1; i < series.x.size(); ++i) {
        if (!finite(series.x[i - 1]) || !finite(series.y[i - 1]) || !finite(series.x[i]) ||
            !finite(series.y[i])) {
          continue;
        }
        cv::line(area,
                 {fixed(x.toPx(series.x[i - 1]) - plot.x), fixed(y.toPx(series.y[i - 1]) - plot.y)},
                 {fixed(x.toPx(series.x[i]) - plot.x), fixed(y.toPx(series.y[i]) - plot.y)}, colour,
                 2, cv::LINE_AA, kShift);
      }
    }
    const int radius = input.linesJoined ? 4 : 2;
    for (std::size_t i = 0; i < series.x.size(); ++i) {
      if (finite(series.x[i]) && finite(series.y[i]) && inside(series.x[i], series.y[i])) {
        cv::circle(canvas, {fixed(x.toPx(series.x[i])), fixed(y.toPx(series.y[i]))},
                   radius << kShift, colour, cv::FILLED, cv::LINE_AA, kShift);
      }
    }
  }
  drawAxisLines(canvas, plot);
  chart.image = toRgbImage(canvas);
  return chart;
}

std::expected<void, std::string> write(const std::filesystem::path& png,
                                       const std::expected<Chart, std::string>& chart) {
  if (!chart) {
    return std::unexpected(chart.error());
  }
  return guarded("PNG", [&] { return sim::writePngRgb8(png, chart->image.view()); });
}

}  // namespace

algo::Rgb8 seriesColour(std::size_t index) {
  return kPalette[index % kPalette.size()];
}

std::expected<Chart, std::string> renderErrorMap(std::span<const float> errorsMm, int width,
                                                 int height, double rangeMm,
                                                 const std::string& title) {
  return guarded("error map", [&] { return errorMap(errorsMm, width, height, rangeMm, title); });
}

std::expected<void, std::string> writeErrorMap(const std::filesystem::path& png,
                                               std::span<const float> errorsMm, int width,
                                               int height, double rangeMm,
                                               const std::string& title) {
  return write(png, renderErrorMap(errorsMm, width, height, rangeMm, title));
}

std::expected<Chart, std::string> renderBarChart(const BarChart& chart) {
  return guarded("bar chart", [&] { return barChart(chart); });
}

std::expected<void, std::string> writeBarChart(const std::filesystem::path& png,
                                               const BarChart& chart) {
  return write(png, renderBarChart(chart));
}

std::expected<Chart, std::string> renderLineChart(const LineChart& chart) {
  return guarded("line chart", [&] { return lineChart(chart); });
}

std::expected<void, std::string> writeLineChart(const std::filesystem::path& png,
                                                const LineChart& chart) {
  return write(png, renderLineChart(chart));
}

}  // namespace smx::plots
