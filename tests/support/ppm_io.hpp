#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <vector>

#include "smx/algo/image_view.hpp"

// Binary PPM (P6, 8 bits per channel): how test programs hand a rendered camera frame to code
// built without a PNG library (the board build, a qemu guest). Standard library + smx_algo only.
namespace smx::test {

struct PpmImage {
  int width = 0;
  int height = 0;
  std::vector<algo::Rgb8> pixels;  // row-major, packed
};

// Every failure names the file and what is wrong with it.
[[nodiscard]] std::expected<PpmImage, std::string> readPpm(const std::filesystem::path& path);
[[nodiscard]] std::expected<void, std::string> writePpm(const std::filesystem::path& path,
                                                        algo::ConstRgbView image);

}  // namespace smx::test
