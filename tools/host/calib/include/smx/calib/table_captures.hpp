#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/calib/turntable_axis.hpp"

// The turntable's axis from a folder of captures (`stripemux calibrate --turntable`,
// docs/calibration.md "Turntable axis"):
//
//     DIR/target.json                  the printed target (stripemux-target/1)
//     DIR/turntable.json               {"format": "stripemux-table-captures/1",
//                                       "views": [{"id": "view00", "angle_deg": -40}, …]}
//     DIR/<id>/<camera-id>.png         the target on the table, every projector off
//
// The rig's cameras must already be calibrated: the target's pose in each view comes from its
// corners and the rig's lens.
namespace smx::calib {

inline constexpr std::string_view kTableCapturesFormat = "stripemux-table-captures/1";
inline constexpr int kMaxTableViews = 360;

struct TableViewUse {
  std::string id;
  double angleDeg = 0.0;
  std::string camera;  // the camera whose corners placed the target; empty when not used
  std::string note;    // why not used, or empty
};

struct TableCalibration {
  AxisFit axis;
  std::vector<TableViewUse> views;
};

[[nodiscard]] std::expected<TableCalibration, std::string> calibrateTable(
    const algo::Rig& rig, const std::filesystem::path& dir);

// The summary `calibrate --turntable` prints.
[[nodiscard]] std::string tableReportText(const TableCalibration& calibration);

}  // namespace smx::calib
