#pragma once

#include <expected>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "output_folder.hpp"
#include "smx/scan/range_view.hpp"
#include "smx/scan/views_folder.hpp"

// A scan's views as they arrive (docs/scanning.md "The views folder"): DIR/rig.json first, then
// each view's DIR/views/<id>/<cam>.depth.png (and .colour.png) committed as it is written, so a
// scan that breaks keeps the views it took whole; DIR/views/views.json at the end lists them
// with their angles and poses.
namespace smx::host {

class ViewsWriter {
 public:
  // `rigJson`: the rig the views were decoded with, as the device sent it.
  [[nodiscard]] static std::expected<ViewsWriter, std::string> create(
      const std::filesystem::path& dir, const algo::Rig& rig, std::string_view rigJson,
      scan::ScanMode mode);

  [[nodiscard]] std::expected<void, std::string> add(const scan::RangeView& view);
  // views.json with `poses` (one per view added, or empty).
  [[nodiscard]] std::expected<void, std::string> finish(
      const std::vector<std::optional<scan::Pose>>& poses);

  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }

 private:
  ViewsWriter(std::filesystem::path dir, algo::Rig rig, scan::ScanMode mode)
      : dir_(std::move(dir)), rig_(std::move(rig)), mode_(mode) {}

  std::filesystem::path dir_;
  algo::Rig rig_;
  scan::ScanMode mode_;
  double depthUnitM_ = 0.0;
  std::vector<scan::ViewEntry> entries_;
};

}  // namespace smx::host
