#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

#include "smx/sim/pfm_io.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::sim {
namespace {

namespace fs = std::filesystem;

fs::path tempFile(const std::string& name) {
  return fs::temp_directory_path() / ("smx_sim_io_" + name);
}

// Given a 3x2 grey float image, when written as PFM, then the bytes follow the format: header
// "Pf", width height, -1 (little endian), then rows from the bottom up.
TEST(SimIo, GreyPfmLayoutFollowsTheFormat) {
  std::vector<float> px = {1, 2, 3, 4, 5, std::numeric_limits<float>::quiet_NaN()};
  const auto view = *algo::ImageView<const float>::packed(px, 3, 2);
  const auto path = tempFile("grey.pfm");
  ASSERT_TRUE(writePfm(path, view).has_value());
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const std::string header = "Pf\n3 2\n-1.0\n";
  ASSERT_EQ(bytes.size(), header.size() + 6 * sizeof(float));
  EXPECT_EQ(bytes.substr(0, header.size()), header);
  float first = 0;
  std::memcpy(&first, bytes.data() + header.size(), sizeof(float));
  EXPECT_EQ(first, 4.0F);  // bottom row first

  const auto back = readPfm(path);
  ASSERT_TRUE(back.has_value()) << back.error();
  EXPECT_EQ(back->channels, 1);
  EXPECT_EQ(back->values[0], 1.0F);
  EXPECT_EQ(back->values[4], 5.0F);
  EXPECT_TRUE(std::isnan(back->values[5]));
  fs::remove(path);
}

TEST(SimIo, ColourPfmRoundTrips) {
  std::vector<std::array<float, 3>> px = {{0.1F, 0.2F, 0.3F}, {-1, 0, 1}};
  const auto path = tempFile("colour.pfm");
  ASSERT_TRUE(writePfm(path, *algo::ImageView<const std::array<float, 3>>::packed(px, 1, 2)));
  const auto back = readPfm(path);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->channels, 3);
  EXPECT_EQ(back->values, (std::vector<float>{0.1F, 0.2F, 0.3F, -1, 0, 1}));
  fs::remove(path);
}

TEST(SimIo, TruncatedOrForeignPfmIsRejectedWithTheFileName) {
  const auto path = tempFile("bad.pfm");
  std::ofstream(path) << "Pf\n4 4\n-1.0\nxx";
  const auto truncated = readPfm(path);
  ASSERT_FALSE(truncated.has_value());
  EXPECT_NE(truncated.error().find("truncated"), std::string::npos);
  EXPECT_NE(truncated.error().find(path.string()), std::string::npos);
  std::ofstream(path) << "P6\n4 4\n255\n";
  EXPECT_FALSE(readPfm(path).has_value());
  fs::remove(path);
}

TEST(SimIo, GreyAndRgbPngRoundTrip) {
  std::vector<std::uint8_t> mask = {0, 255, 7, 0, 128, 255};
  const auto maskPath = tempFile("mask.png");
  ASSERT_TRUE(writePngGray8(maskPath, *algo::ImageView<const std::uint8_t>::packed(mask, 3, 2)));
  const auto asRgb = readPngRgb8(maskPath);
  ASSERT_TRUE(asRgb.has_value());
  EXPECT_EQ(asRgb->pixels[1], (algo::Rgb8{255, 255, 255}));
  EXPECT_EQ(asRgb->pixels[2], (algo::Rgb8{7, 7, 7}));
  fs::remove(maskPath);

  // A padded RGB view is written without its padding.
  std::vector<std::byte> padded(2 * 8);
  auto view = *algo::RgbView::create(padded.data(), 2, 2, 8);
  view(0, 0) = {1, 2, 3};
  view(1, 1) = {250, 251, 252};
  const auto rgbPath = tempFile("rgb.png");
  ASSERT_TRUE(writePngRgb8(rgbPath, view));
  const auto back = readPngRgb8(rgbPath);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->pixels[0], (algo::Rgb8{1, 2, 3}));
  EXPECT_EQ(back->pixels[3], (algo::Rgb8{250, 251, 252}));
  EXPECT_FALSE(readPngRgb8(tempFile("missing.png")).has_value());
  fs::remove(rgbPath);
}

}  // namespace
}  // namespace smx::sim
