#pragma once

#include <array>
#include <expected>
#include <filesystem>
#include <string>
#include <vector>

#include "smx/algo/image_view.hpp"

// PFM (Portable Float Map) files for ground truth: 32-bit float, 1 channel ("Pf") or 3 ("PF"),
// little-endian (scale −1), rows stored bottom to top as the format requires. NaN is kept.
namespace smx::sim {

struct FloatImage {
  int width = 0;
  int height = 0;
  int channels = 1;           // 1 or 3
  std::vector<float> values;  // row-major from the top row, channels interleaved
};

[[nodiscard]] std::expected<void, std::string> writePfm(const std::filesystem::path& path,
                                                        algo::ImageView<const float> image);
[[nodiscard]] std::expected<void, std::string> writePfm(
    const std::filesystem::path& path, algo::ImageView<const std::array<float, 3>> image);

[[nodiscard]] std::expected<FloatImage, std::string> readPfm(const std::filesystem::path& path);

}  // namespace smx::sim
