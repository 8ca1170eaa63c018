#pragma once

#include <cstdint>
#include <expected>
#include <span>
#include <string>
#include <string_view>

#include "output_folder.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/sim/pfm_io.hpp"
#include "smx/sim/ply_io.hpp"
#include "smx/sim/png_io.hpp"

// The file kinds the commands write, each into an OutputFolder (names checked, complete or absent).
namespace smx::host {

// A camera's range image and its confidence plane, side by side (docs/cli.md); `stem` is the
// camera's id, or id_frame in a stream.
[[nodiscard]] inline std::string depthPngName(std::string_view stem) {
  return std::string(stem) + ".depth.png";
}
[[nodiscard]] inline std::string confidencePngName(std::string_view stem) {
  return std::string(stem) + ".confidence.png";
}

[[nodiscard]] inline std::expected<void, std::string> writePngRgb8(OutputFolder& folder,
                                                                   std::string_view name,
                                                                   algo::ConstRgbView image) {
  return folder.write(name, [&](const auto& file) { return sim::writePngRgb8(file, image); });
}

[[nodiscard]] inline std::expected<void, std::string> writePngGray8(
    OutputFolder& folder, std::string_view name, algo::ImageView<const std::uint8_t> image) {
  return folder.write(name, [&](const auto& file) { return sim::writePngGray8(file, image); });
}

[[nodiscard]] inline std::expected<void, std::string> writePngGray16(
    OutputFolder& folder, std::string_view name, algo::ImageView<const std::uint16_t> image) {
  return folder.write(name, [&](const auto& file) { return sim::writePngGray16(file, image); });
}

[[nodiscard]] inline std::expected<void, std::string> writePlyPoints(
    OutputFolder& folder, std::string_view name, std::span<const sim::PlyPoint> points) {
  return folder.write(name, [&](const auto& file) { return sim::writePlyPoints(file, points); });
}

template <class Pixel>
[[nodiscard]] std::expected<void, std::string> writePfm(OutputFolder& folder, std::string_view name,
                                                        algo::ImageView<const Pixel> image) {
  return folder.write(name, [&](const auto& file) { return sim::writePfm(file, image); });
}

}  // namespace smx::host
