#pragma once

#include <cstdint>
#include <expected>
#include <filesystem>
#include <string>
#include <vector>

#include "smx/algo/image_view.hpp"

// PNG files for the host tool and the simulated camera (libpng's simplified API). Errors are
// messages naming the file.
namespace smx::sim {

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

// A 16-bit grey PNG as written above; any other kind is an error naming the file and its kind.
[[nodiscard]] std::expected<Gray16Image, std::string> readPngGray16(
    const std::filesystem::path& path);

// Any PNG (grey, palette, 16-bit, alpha) converted to 8-bit RGB.
[[nodiscard]] std::expected<RgbImage, std::string> readPngRgb8(const std::filesystem::path& path);

}  // namespace smx::sim
