#pragma once

#include <cstdint>
#include <expected>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/scan/range_view.hpp"

// The recorded views of a scan on disk (docs/scanning.md "The views folder"): a `scan` folder
// (rig.json + views/views.json + views/<id>/<cam>.depth.png, .colour.png) or a `stream` folder
// (rig.json + <cam>_<n>.depth.png). Every name is checked, every image's size checked against
// the rig before its pixels are allocated; errors name the file and the field.
namespace smx::scan {

inline constexpr std::string_view kViewsFormat = "stripemux-views/1";

enum class ScanMode { kTurntable, kHandheld, kStream };

struct ViewsFolder {
  algo::Rig rig{};
  ScanMode mode = ScanMode::kStream;
  std::vector<RangeView> views{};            // in capture order
  std::vector<std::optional<Pose>> poses{};  // one per view; set where views.json gives one
  std::optional<TurntableAxis> axis{};  // rig.json "turntable", else views.json "turntable_axis"
};

// Reads DIR: DIR/views/views.json when present, else a stream folder's <cam>_<n>.depth.png
// (frames with every rig camera's image; depth unit from DIR/summary.json "depth_unit_m", else
// 1e-4 m). At most `maxViews` views are read.
[[nodiscard]] std::expected<ViewsFolder, std::string> readViewsFolder(
    const std::filesystem::path& dir, std::size_t maxViews = 1000);

// One entry of views.json.
struct ViewEntry {
  std::string id{};  // a name: 1–64 of A-Z a-z 0-9 _ -
  std::int64_t captureNs = 0;
  std::optional<double> turntableDeg{};
  std::optional<Pose> pose{};  // rig → model
};

// views.json's text (for the `scan` command, which writes the PNGs itself with
// sim::writePngGray16 / writePngRgb8 as views/<id>/<cam-id>.depth.png / .colour.png).
[[nodiscard]] std::string viewsJson(ScanMode mode, double depthUnitM,
                                    const std::vector<ViewEntry>& views,
                                    const std::optional<TurntableAxis>& axis = std::nullopt);

// poses.json: {"format": "stripemux-poses/1", "poses": [{"id": …, "pose": [16 numbers]}]}.
[[nodiscard]] std::string posesJson(const std::vector<std::string>& ids,
                                    const std::vector<Pose>& poses);

// Why `id` is not a view id (see ViewEntry::id), or nullopt.
[[nodiscard]] std::optional<std::string> viewIdProblem(std::string_view id);

}  // namespace smx::scan
