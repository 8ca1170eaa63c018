#pragma once

#include <cstddef>
#include <cstdint>
#include <expected>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "smx/algo/image_view.hpp"

// PNG files for the host tool and the simulated camera (libpng's simplified API). Errors are
// messages naming the file.
//
// A PNG's header can claim any size up to 2^31 - 1 pixels a side in a few dozen bytes, so every
// reader checks the claim against a PngSizeLimit before it allocates the pixels.
namespace smx::sim {

// The largest PNG any reader accepts: 16384 pixels a side and 64 Mpixel in all, more than any
// machine-vision sensor or scene texture in use, and at most 192 MiB as 8-bit RGB.
inline constexpr int kPngMaxSide = 16384;
inline constexpr std::uint64_t kPngMaxPixels = std::uint64_t{1} << 26U;

// The sizes a reader accepts, checked against the file's header before any pixel is allocated.
struct PngSizeLimit {
  int width = 0;   // exactly this size when both are > 0 (a camera's image); in any case
  int height = 0;  // within the maxima
  std::string_view owner = "the expected size";  // whose size width x height is, for errors
  int maxSide = kPngMaxSide;
  std::uint64_t maxPixels = kPngMaxPixels;

  // An image of exactly width x height, e.g. exactly(640, 480, "camera cam0").
  [[nodiscard]] static PngSizeLimit exactly(int width, int height, std::string_view owner) {
    return {.width = width, .height = height, .owner = owner};
  }
};

// The bytes a PNG file within `limit` can take (its pixels at 8 bytes each, the largest kind,
// plus 16 MiB of other chunks): the file readers refuse larger files before reading them.
[[nodiscard]] std::uint64_t maxPngFileBytes(const PngSizeLimit& limit);

struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<algo::Rgb8> pixels;  // row-major, packed

  [[nodiscard]] algo::ConstRgbView view() const {
    return *algo::ConstRgbView::packed(pixels, width, height);
  }
};

[[nodiscard]] std::expected<void, std::string> writePngRgb8(const std::filesystem::path& path,
                                                            algo::ConstRgbView image);

// 8-bit grey (masks).
[[nodiscard]] std::expected<void, std::string> writePngGray8(
    const std::filesystem::path& path, algo::ImageView<const std::uint8_t> image);

// 16-bit grey, samples stored exactly (linear, no gamma conversion): depth images in depth
// units, as OpenCV (IMREAD_ANYDEPTH) and Open3D read them.
[[nodiscard]] std::expected<void, std::string> writePngGray16(
    const std::filesystem::path& path, algo::ImageView<const std::uint16_t> image);

struct Gray16Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> pixels;  // row-major, packed

  [[nodiscard]] algo::ImageView<const std::uint16_t> view() const {
    return *algo::ImageView<const std::uint16_t>::packed(pixels, width, height);
  }
};

// A 16-bit grey PNG as written above; any other kind is an error naming the file and its kind,
// a size outside `limit` one naming the file and both sizes.
[[nodiscard]] std::expected<Gray16Image, std::string> readPngGray16(
    const std::filesystem::path& path, const PngSizeLimit& limit = {});

// Any PNG (grey, palette, 16-bit, alpha) converted to 8-bit RGB; sizes as for readPngGray16.
[[nodiscard]] std::expected<RgbImage, std::string> readPngRgb8(const std::filesystem::path& path,
                                                               const PngSizeLimit& limit = {});

// The same readers on a PNG in memory (what the file readers use after reading the file);
// `name` stands for the file in errors.
[[nodiscard]] std::expected<Gray16Image, std::string> readPngGray16(
    std::span<const std::byte> bytes, std::string_view name, const PngSizeLimit& limit = {});
[[nodiscard]] std::expected<RgbImage, std::string> readPngRgb8(std::span<const std::byte> bytes,
                                                               std::string_view name,
                                                               const PngSizeLimit& limit = {});

}  // namespace smx::sim
