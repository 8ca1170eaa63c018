#include "scan_views_writer.hpp"

#include "output_files.hpp"

namespace smx::host {

namespace fs = std::filesystem;

std::expected<ViewsWriter, std::string> ViewsWriter::create(const fs::path& dir,
                                                            const algo::Rig& rig,
                                                            std::string_view rigJson,
                                                            scan::ScanMode mode) {
  auto top = OutputFolder::create(dir);
  if (!top) {
    return std::unexpected(top.error());
  }
  if (auto ok = top->writeText("rig.json", std::string(rigJson)); !ok) {
    return std::unexpected(ok.error());
  }
  if (auto ok = top->commit(); !ok) {
    return std::unexpected(ok.error());
  }
  return ViewsWriter(dir, rig, mode);
}

std::expected<void, std::string> ViewsWriter::add(const scan::RangeView& view) {
  if (const auto problem = scan::viewIdProblem(view.id)) {
    return std::unexpected("view id " + view.id + ": " + *problem);
  }
  if (view.cameras.size() != rig_.cameras.size()) {
    return std::unexpected("view " + view.id + ": " + std::to_string(view.cameras.size()) +
                           " camera images for a rig of " + std::to_string(rig_.cameras.size()));
  }
  auto folder = OutputFolder::create(dir_ / "views" / view.id);
  if (!folder) {
    return std::unexpected(folder.error());
  }
  for (std::size_t c = 0; c < view.cameras.size(); ++c) {
    const auto& range = view.cameras[c];
    const std::string& id = rig_.cameras[c].id;
    const auto depth = algo::ImageView<const std::uint16_t>::packed(
        std::span<const std::uint16_t>(range.depth), range.width, range.height);
    if (!depth) {
      return std::unexpected("view " + view.id + ", " + id + ": " + depth.error().message);
    }
    if (auto ok = writePngGray16(*folder, depthPngName(id), *depth); !ok) {
      return std::unexpected(ok.error());
    }
    if (!range.colour.empty()) {
      std::vector<algo::Rgb8> pixels;
      pixels.reserve(range.colour.size());
      for (const auto& [r, g, b] : range.colour) {
        pixels.push_back({r, g, b});
      }
      const auto colour = algo::ImageView<const algo::Rgb8>::packed(
          std::span<const algo::Rgb8>(pixels), range.width, range.height);
      if (!colour) {
        return std::unexpected("view " + view.id + ", " + id + ": " + colour.error().message);
      }
      if (auto ok = writePngRgb8(*folder, id + ".colour.png", *colour); !ok) {
        return std::unexpected(ok.error());
      }
    }
  }
  if (auto ok = folder->commit(); !ok) {
    return std::unexpected(ok.error());
  }
  depthUnitM_ = view.depthUnitM;
  entries_.push_back(
      {.id = view.id, .captureNs = view.captureNs, .turntableDeg = view.turntableDeg, .pose = {}});
  return {};
}

std::expected<void, std::string> ViewsWriter::finish(
    const std::vector<std::optional<scan::Pose>>& poses) {
  for (std::size_t i = 0; i < entries_.size() && i < poses.size(); ++i) {
    entries_[i].pose = poses[i];
  }
  auto folder = OutputFolder::create(dir_ / "views");
  if (!folder) {
    return std::unexpected(folder.error());
  }
  if (auto ok = folder->writeText("views.json", scan::viewsJson(mode_, depthUnitM_, entries_));
      !ok) {
    return ok;
  }
  return folder->commit();
}

}  // namespace smx::host
