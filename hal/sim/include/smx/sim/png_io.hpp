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

// Any PNG (grey, palette, 16-bit, alpha) converted to 8-bit RGB.
[[nodiscard]] std::expected<RgbImage, std::string> readPngRgb8(const std::filesystem::path& path);

}  // namespace smx::sim
