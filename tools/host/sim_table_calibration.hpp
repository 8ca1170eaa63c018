#pragma once

#include <span>
#include <string>
#include <vector>

#include "sim_calibration.hpp"

// Simulated captures for the turntable's axis (`stripemux sim --table-calibration N`,
// docs/calibration.md "Turntable axis"): the printed target leaning on the table, facing the
// cameras, seen with the projectors off at N table angles, with the true axis.
namespace smx::host {

inline constexpr std::string_view kTableCapturesFormat = "stripemux-table-captures/1";

// A table's axis in the rig's world frame: a unit direction and a point on it.
struct TableLine {
  sim::Vec3 direction = -sim::Vec3::UnitY();  // up, in a rig whose y points down
  sim::Vec3 point = sim::Vec3::Zero();
};

// A vertical table (world up) under the first camera's optical axis at the rig's working
// distance, its top 10 cm below that axis.
[[nodiscard]] TableLine defaultTableLine(const algo::Rig& rig);

// `count` angles spread evenly over ±40°: the target faces the cameras at every one.
[[nodiscard]] std::vector<double> tableAngles(int count);

// The target leaning back 50° with its centre on the axis, turned by each angle about the line.
[[nodiscard]] std::vector<TargetPose> tableTargetPoses(const calib::Target& target,
                                                       const TableLine& line,
                                                       std::span<const double> anglesDeg);

// "view00", "view01", …
[[nodiscard]] std::string tableViewName(int index);

// DIR/turntable.json text: the format and each view's folder and commanded angle.
[[nodiscard]] std::string tableCapturesJson(std::span<const double> anglesDeg);

// DIR/truth/axis.json text.
[[nodiscard]] std::string tableLineJson(const TableLine& line);

}  // namespace smx::host
