#include "smx/plots/plots.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace smx::plots {
namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();

algo::Rgb8 at(const sim::RgbImage& image, int x, int y) {
  return image.pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                      static_cast<std::size_t>(x)];
}

bool isWhitish(algo::Rgb8 c) {
  return c.r >= 245 && c.g >= 245 && c.b >= 245;
}
bool isRed(algo::Rgb8 c) {
  return c.r > 150 && c.g < 60 && c.b < 60;
}
bool isBlue(algo::Rgb8 c) {
  return c.b > 150 && c.r < 60 && c.g < 130;
}
bool isDarkGrey(algo::Rgb8 c) {
  return c.r == c.g && c.g == c.b && c.r < 128;
}

// Pixels of exactly this colour in columns [x0, x1) and rows [y0, y1).
int countColour(const sim::RgbImage& image, algo::Rgb8 colour, int x0, int x1, int y0, int y1) {
  int n = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      n += at(image, x, y) == colour ? 1 : 0;
    }
  }
  return n;
}

// The tallest run of the colour in any one column of [x0, x1), within rows [y0, y1).
int tallestColumn(const sim::RgbImage& image, algo::Rgb8 colour, int x0, int x1, int y0, int y1) {
  int tallest = 0;
  for (int x = x0; x < x1; ++x) {
    tallest = std::max(tallest, countColour(image, colour, x, x + 1, y0, y1));
  }
  return tallest;
}

bool colourNear(const sim::RgbImage& image, algo::Rgb8 colour, int x, int y, int radius) {
  return countColour(image, colour, x - radius, x + radius + 1, y - radius, y + radius + 1) > 0;
}

std::vector<unsigned char> firstBytes(const fs::path& path, std::size_t n) {
  std::ifstream in(path, std::ios::binary);
  std::vector<unsigned char> bytes(n);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(n));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  return bytes;
}

// ---- Error map ----

// Given errors of 0, +range, 3x range, -range and NaN, when rendered, then they come out white,
// the red end (the same for both: clipped), the blue end and dark grey.
TEST(PlotsErrorMap, ColoursFollowTheDivergingScale) {
  const std::vector<float> errors = {0.0F, 2.0F, 6.0F, -2.0F, kNaNf, 1.0F};
  const auto chart = renderErrorMap(errors, 6, 1, 2.0, "scale");
  ASSERT_TRUE(chart.has_value()) << chart.error();
  const auto pixel = [&](int x) { return at(chart->image, chart->plot.x + x, chart->plot.y); };
  EXPECT_TRUE(isWhitish(pixel(0)));
  EXPECT_TRUE(isRed(pixel(1)));
  EXPECT_EQ(pixel(2), pixel(1));
  EXPECT_TRUE(isBlue(pixel(3)));
  EXPECT_TRUE(isDarkGrey(pixel(4)));
  // Half the range lies between white and the red end.
  EXPECT_GT(pixel(5).g, pixel(1).g);
  EXPECT_LT(pixel(5).g, pixel(0).g);
}

// Given an odd-sized image whose pixels are -range, 0, +range or NaN in a seeded random order,
// when rendered, then every input pixel appears unscaled at a fixed offset: each output pixel
// has its input's colour class.
TEST(PlotsErrorMap, ImageIsCopiedOneToOneAtAFixedOffset) {
  constexpr int kWidth = 13;
  constexpr int kHeight = 7;
  const std::array<float, 4> kinds = {-1.0F, 0.0F, 1.0F, kNaNf};
  std::mt19937 random(7);
  std::vector<std::size_t> kind(std::size_t{kWidth} * kHeight);
  std::vector<float> errors(kind.size());
  for (std::size_t i = 0; i < kind.size(); ++i) {
    kind[i] = random() % kinds.size();
    errors[i] = kinds[kind[i]];
  }
  const auto chart = renderErrorMap(errors, kWidth, kHeight, 1.0, "random");
  ASSERT_TRUE(chart.has_value()) << chart.error();
  EXPECT_EQ(chart->plot.x, kErrorMapLeftPx);
  EXPECT_EQ(chart->plot.y, kErrorMapTopPx);
  EXPECT_EQ(chart->plot.width, kWidth);
  EXPECT_EQ(chart->plot.height, kHeight);
  const std::array<bool (*)(algo::Rgb8), 4> classes = {isBlue, isWhitish, isRed, isDarkGrey};
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const std::size_t k =
          kind[static_cast<std::size_t>(y) * kWidth + static_cast<std::size_t>(x)];
      EXPECT_TRUE(classes[k](at(chart->image, kErrorMapLeftPx + x, kErrorMapTopPx + y)))
          << x << "," << y << " kind " << k;
    }
  }

  // A 1x1 image starts at the same place.
  const std::vector<float> one = {0.0F};
  const auto small = renderErrorMap(one, 1, 1, 1.0, "");
  ASSERT_TRUE(small.has_value()) << small.error();
  EXPECT_EQ(small->plot.x, kErrorMapLeftPx);
  EXPECT_EQ(small->plot.y, kErrorMapTopPx);
  EXPECT_TRUE(isWhitish(at(small->image, kErrorMapLeftPx, kErrorMapTopPx)));
}

// Given an error map, then right of the image there is a colour bar with the red end above the
// blue end.
TEST(PlotsErrorMap, ColourBarHasRedAboveBlue) {
  const std::vector<float> errors = {-5.0F, 5.0F};
  const auto chart = renderErrorMap(errors, 2, 1, 5.0, "bar");
  ASSERT_TRUE(chart.has_value()) << chart.error();
  const algo::Rgb8 blue = at(chart->image, chart->plot.x, chart->plot.y);
  const algo::Rgb8 red = at(chart->image, chart->plot.x + 1, chart->plot.y);
  int redRow = -1;
  int blueRow = -1;
  const int right = chart->plot.x + chart->plot.width + 1;
  for (int y = 0; y < chart->image.height; ++y) {
    if (redRow < 0 && countColour(chart->image, red, right, chart->image.width, y, y + 1) > 0) {
      redRow = y;
    }
    if (blueRow < 0 && countColour(chart->image, blue, right, chart->image.width, y, y + 1) > 0) {
      blueRow = y;
    }
  }
  ASSERT_GE(redRow, 0);
  ASSERT_GE(blueRow, 0);
  EXPECT_LT(redRow, blueRow);
  EXPECT_GT(blueRow - redRow, 100);  // a bar, not a swatch
}

TEST(PlotsErrorMap, RejectsBadInput) {
  const std::vector<float> six(6, 0.0F);
  const auto wrongSize = renderErrorMap(six, 4, 2, 1.0, "t");
  ASSERT_FALSE(wrongSize.has_value());
  EXPECT_NE(wrongSize.error().find("6 errors"), std::string::npos) << wrongSize.error();
  EXPECT_NE(wrongSize.error().find("4x2"), std::string::npos) << wrongSize.error();

  const auto zeroRange = renderErrorMap(six, 3, 2, 0.0, "t");
  ASSERT_FALSE(zeroRange.has_value());
  EXPECT_NE(zeroRange.error().find("range"), std::string::npos) << zeroRange.error();
  EXPECT_FALSE(renderErrorMap(six, 3, 2, -1.0, "t").has_value());
  EXPECT_FALSE(renderErrorMap(six, 3, 2, kNaN, "t").has_value());

  const auto empty = renderErrorMap({}, 0, 0, 1.0, "t");
  ASSERT_FALSE(empty.has_value());
  EXPECT_NE(empty.error().find("size"), std::string::npos) << empty.error();
}

// ---- Bar chart ----

BarChart twoSeriesChart() {
  BarChart chart;
  chart.title = "Valid pixels";
  chart.yLabel = "fraction";
  chart.categories = {"plane", "sphere"};
  chart.series = {"all lit", "lit by 2"};
  chart.values = {{1.0, 0.5}, {kNaN, 0.25}};
  return chart;
}

// Given bars of yMax and yMax/2, when rendered, then the second is half as tall in pixels and
// the first fills the plot's height.
TEST(PlotsBarChart, HalfValueBarIsHalfAsTall) {
  const auto chart = renderBarChart(twoSeriesChart());
  ASSERT_TRUE(chart.has_value()) << chart.error();
  const auto& plot = chart->plot;
  const int half = plot.x + plot.width / 2;
  const algo::Rgb8 colour = seriesColour(0);
  const int full = tallestColumn(chart->image, colour, plot.x, half, plot.y, plot.y + plot.height);
  const int halfBar =
      tallestColumn(chart->image, colour, half, plot.x + plot.width, plot.y, plot.y + plot.height);
  EXPECT_NEAR(full, plot.height, 1);
  EXPECT_NEAR(halfBar, full / 2.0, 1.0);
  // Both stand on the bottom row of the plot; the full one reaches its top row.
  const int bottom = plot.y + plot.height - 1;
  EXPECT_GT(countColour(chart->image, colour, plot.x, half, bottom, bottom + 1), 0);
  EXPECT_GT(countColour(chart->image, colour, half, plot.x + plot.width, bottom, bottom + 1), 0);
  EXPECT_GT(countColour(chart->image, colour, plot.x, half, plot.y, plot.y + 1), 0);
}

// Given a NaN value, then that bar is not drawn, while the same series' other bar is.
TEST(PlotsBarChart, NanDrawsNoBar) {
  const auto chart = renderBarChart(twoSeriesChart());
  ASSERT_TRUE(chart.has_value()) << chart.error();
  const auto& plot = chart->plot;
  const int half = plot.x + plot.width / 2;
  const int bottom = plot.y + plot.height;
  const algo::Rgb8 colour = seriesColour(1);
  EXPECT_EQ(countColour(chart->image, colour, plot.x, half, plot.y, bottom), 0);
  EXPECT_NEAR(tallestColumn(chart->image, colour, half, plot.x + plot.width, plot.y, bottom),
              plot.height / 4.0, 1.0);
}

// Given a range around zero, then a negative value's bar hangs below the middle (zero) row.
TEST(PlotsBarChart, NegativeBarsHangFromZero) {
  BarChart input;
  input.title = "bias";
  input.yMin = -1;
  input.yMax = 1;
  input.categories = {"a"};
  input.series = {"s"};
  input.values = {{-0.5}};
  const auto chart = renderBarChart(input);
  ASSERT_TRUE(chart.has_value()) << chart.error();
  const auto& plot = chart->plot;
  const int middle = plot.y + plot.height / 2;
  const algo::Rgb8 colour = seriesColour(0);
  const int right = plot.x + plot.width;
  EXPECT_EQ(countColour(chart->image, colour, plot.x, right, plot.y, middle - 1), 0);
  EXPECT_NEAR(tallestColumn(chart->image, colour, plot.x, right, middle, plot.y + plot.height),
              plot.height / 4.0, 1.5);
}

// Given many long category names, then the chart still renders at its size with every bar.
TEST(PlotsBarChart, LongCategoryNamesStillRender) {
  BarChart input;
  input.series = {"only"};
  input.values.resize(1);
  for (int i = 0; i < 12; ++i) {
    input.categories.push_back("a rather long scene name " + std::to_string(i));
    input.values[0].push_back(0.1 * i);
  }
  const auto chart = renderBarChart(input);
  ASSERT_TRUE(chart.has_value()) << chart.error();
  EXPECT_EQ(chart->image.width, kChartWidth);
  EXPECT_EQ(chart->image.height, kChartHeight);
  EXPECT_GT(chart->plot.height, kChartHeight / 3);
}

TEST(PlotsBarChart, RejectsBadInput) {
  BarChart noCategories = twoSeriesChart();
  noCategories.categories.clear();
  const auto a = renderBarChart(noCategories);
  ASSERT_FALSE(a.has_value());
  EXPECT_NE(a.error().find("no categories"), std::string::npos) << a.error();

  BarChart shortRow = twoSeriesChart();
  shortRow.values[1].pop_back();
  const auto b = renderBarChart(shortRow);
  ASSERT_FALSE(b.has_value());
  EXPECT_NE(b.error().find("'lit by 2' has 1 values for 2 categories"), std::string::npos)
      << b.error();

  BarChart missingRow = twoSeriesChart();
  missingRow.values.pop_back();
  const auto c = renderBarChart(missingRow);
  ASSERT_FALSE(c.has_value());
  EXPECT_NE(c.error().find("values"), std::string::npos) << c.error();

  BarChart emptyRange = twoSeriesChart();
  emptyRange.yMax = emptyRange.yMin;
  const auto d = renderBarChart(emptyRange);
  ASSERT_FALSE(d.has_value());
  EXPECT_NE(d.error().find("y range"), std::string::npos) << d.error();
}

// ---- Line chart ----

// Given explicit ranges, when rendered, then each point's marker is at the pixel the ranges put
// it at, and the axis lines border the plot area.
TEST(PlotsLineChart, PointsLandOnTheirPixels) {
  LineChart input;
  input.title = "map";
  input.xLabel = "x";
  input.yLabel = "y";
  input.linesJoined = false;
  input.xRange = {{0.0, 10.0}};
  input.yRange = {{0.0, 100.0}};
  input.series = {{"a", {2, 5, 8}, {20, 50, 90}}, {"b", {9}, {10}}};
  const auto chart = renderLineChart(input);
  ASSERT_TRUE(chart.has_value()) << chart.error();
  const auto& plot = chart->plot;
  const auto column = [&](double x) {
    return static_cast<int>(std::lround(plot.x + x / 10.0 * (plot.width - 1)));
  };
  const auto row = [&](double y) {
    return static_cast<int>(std::lround(plot.y + plot.height - 1 - y / 100.0 * (plot.height - 1)));
  };
  for (const auto& s : std::array{0, 1}) {
    const Series& series = input.series[static_cast<std::size_t>(s)];
    for (std::size_t i = 0; i < series.x.size(); ++i) {
      EXPECT_TRUE(colourNear(chart->image, seriesColour(static_cast<std::size_t>(s)),
                             column(series.x[i]), row(series.y[i]), 1))
          << series.label << " point " << i;
    }
  }
  // Nothing of series a where it has no point (a dot is 2 px in radius).
  EXPECT_FALSE(colourNear(chart->image, seriesColour(0), column(5), row(20), 4));
  // The axes: dark grey along the column left of the plot and the row below it.
  for (const int y : {plot.y, plot.y + plot.height / 2, plot.y + plot.height - 1}) {
    EXPECT_TRUE(isDarkGrey(at(chart->image, plot.x - 1, y))) << y;
    EXPECT_FALSE(isDarkGrey(at(chart->image, plot.x, y))) << y;
  }
  for (const int x : {plot.x, plot.x + plot.width / 2, plot.x + plot.width - 1}) {
    EXPECT_TRUE(isDarkGrey(at(chart->image, x, plot.y + plot.height))) << x;
  }
}

// Given points joined by lines with a NaN between two of them, then there is a line between
// joined points and a gap at the NaN.
TEST(PlotsLineChart, LinesJoinFinitePointsOnly) {
  LineChart input;
  input.xRange = {{0.0, 4.0}};
  input.yRange = {{0.0, 4.0}};
  input.series = {{"s", {0, 1, 2, 3, 4}, {0, 1, 2, kNaN, 4}}};
  const auto chart = renderLineChart(input);
  ASSERT_TRUE(chart.has_value()) << chart.error();
  const auto& plot = chart->plot;
  const auto pixel = [&](double v, bool isX) {
    return static_cast<int>(
        std::lround(isX ? plot.x + v / 4.0 * (plot.width - 1)
                        : plot.y + plot.height - 1 - v / 4.0 * (plot.height - 1)));
  };
  // Halfway along the segment (0, 0)-(1, 1): the line.
  EXPECT_TRUE(colourNear(chart->image, seriesColour(0), pixel(0.5, true), pixel(0.5, false), 1));
  // Halfway between (2, 2) and (4, 4), where the NaN breaks the line: nothing.
  EXPECT_FALSE(colourNear(chart->image, seriesColour(0), pixel(3.0, true), pixel(3.0, false), 3));
}

// Given no ranges, then every point is inside the plot area, clear of its edges.
TEST(PlotsLineChart, AutomaticRangesKeepPointsInside) {
  LineChart input;
  input.linesJoined = false;
  input.series = {{"s", {-3, 0, 7}, {100, 250, 400}}};
  const auto chart = renderLineChart(input);
  ASSERT_TRUE(chart.has_value()) << chart.error();
  const auto& plot = chart->plot;
  const algo::Rgb8 colour = seriesColour(0);
  const int inset = 5;
  const int all = countColour(chart->image, colour, 0, chart->image.width, 0, chart->image.height);
  const int inside = countColour(chart->image, colour, plot.x + inset, plot.x + plot.width - inset,
                                 plot.y + inset, plot.y + plot.height - inset);
  EXPECT_GT(inside, 0);
  // The legend's swatch is the only other place with the colour.
  EXPECT_GE(inside, all - countColour(chart->image, colour, 0, chart->image.width, 0, plot.y));
}

TEST(PlotsLineChart, RejectsBadInput) {
  const auto none = renderLineChart({});
  ASSERT_FALSE(none.has_value());
  EXPECT_NE(none.error().find("no series"), std::string::npos) << none.error();

  LineChart mismatch;
  mismatch.series = {{"s", {1, 2}, {1, 2, 3}}};
  const auto a = renderLineChart(mismatch);
  ASSERT_FALSE(a.has_value());
  EXPECT_NE(a.error().find("'s' has 2 x values but 3 y values"), std::string::npos) << a.error();

  LineChart badRange;
  badRange.series = {{"s", {1}, {1}}};
  badRange.xRange = {{2.0, 2.0}};
  const auto b = renderLineChart(badRange);
  ASSERT_FALSE(b.has_value());
  EXPECT_NE(b.error().find("x range"), std::string::npos) << b.error();

  LineChart noData;
  noData.series = {{"s", {kNaN}, {1}}};
  const auto c = renderLineChart(noData);
  ASSERT_FALSE(c.has_value());
  EXPECT_NE(c.error().find("no finite points"), std::string::npos) << c.error();
}

// ---- Palette and files ----

TEST(PlotsPalette, SevenDistinctColoursThenRepeats) {
  for (std::size_t i = 0; i < 7; ++i) {
    for (std::size_t j = i + 1; j < 7; ++j) {
      EXPECT_NE(seriesColour(i), seriesColour(j)) << i << " " << j;
    }
    EXPECT_FALSE(isWhitish(seriesColour(i)));
  }
  EXPECT_EQ(seriesColour(7), seriesColour(0));
}

// Given each kind of chart, when written, then the file is a PNG; an unwritable path is an
// error naming it.
TEST(PlotsFiles, WritesPngsAndNamesUnwritablePaths) {
  const fs::path dir = fs::temp_directory_path() / "smx_plots_test";
  fs::create_directories(dir);
  const std::vector<float> errors = {0.0F, 1.0F, -1.0F, kNaNf};
  LineChart line;
  line.series = {{"s", {0, 1}, {0, 1}}};
  ASSERT_TRUE(writeErrorMap(dir / "map.png", errors, 2, 2, 1.0, "map"));
  ASSERT_TRUE(writeBarChart(dir / "bars.png", twoSeriesChart()));
  ASSERT_TRUE(writeLineChart(dir / "line.png", line));
  const std::vector<unsigned char> signature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  for (const char* name : {"map.png", "bars.png", "line.png"}) {
    EXPECT_EQ(firstBytes(dir / name, 8), signature) << name;
  }
  fs::remove_all(dir);

  const fs::path unwritable = "/nonexistent_smx_plots_dir/bars.png";
  const auto failed = writeBarChart(unwritable, twoSeriesChart());
  ASSERT_FALSE(failed.has_value());
  EXPECT_NE(failed.error().find(unwritable.string()), std::string::npos) << failed.error();
  // Bad input is reported before any file is touched.
  BarChart bad = twoSeriesChart();
  bad.categories.clear();
  const auto rejected = writeBarChart(unwritable, bad);
  ASSERT_FALSE(rejected.has_value());
  EXPECT_NE(rejected.error().find("no categories"), std::string::npos) << rejected.error();
}

}  // namespace
}  // namespace smx::plots
