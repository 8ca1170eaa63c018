#pragma once

#include <Eigen/Core>
#include <expected>
#include <span>
#include <string>
#include <vector>

#include "smx/calib/target.hpp"

// The turntable's axis from the printed target lying on the table, seen at several table angles
// (docs/calibration.md, "Turntable axis"): every view's target pose is the first one turned about
// the same line by the table's angle, so the relative rotations give the direction and the
// corners' motion gives a point.
namespace smx::calib {

// A table angles' view: the target's pose in the rig's world frame (X = R·x + t) at the angle
// the table was commanded to.
struct TableView {
  std::string name;  // for messages ("view03")
  double angleDeg = 0.0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
};

// At least this many views spanning this many degrees: two views give a direction and a point,
// the rest average the corner noise and expose a table that slips.
inline constexpr int kMinTableViews = 4;
inline constexpr double kMinTableSpanDeg = 30.0;

struct AxisFit {
  Eigen::Vector3d direction =
      Eigen::Vector3d::UnitY();  // unit; a positive angle turns right-handed about it
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // the axis point nearest the world origin
  // The measured rotation between views over the commanded one: 1 when the table turns as its
  // steps say (a table whose steps per turn are wrong shows it here).
  double angleScale = 1.0;
  double rotationRmsDeg = 0.0;  // measured relative rotations against the fitted axis and angles
  // Every view's corners against the first view's turned about the fitted axis, metres.
  double cornerRmsM = 0.0;
  std::vector<double> viewRmsM;  // per view, the same
};

// Fits the axis to `views` (their targets' poses); the views must share one target. Fails, naming
// what to do, on fewer than kMinTableViews views or an angle span under kMinTableSpanDeg, and when
// the target's rotations are not about one axis (the target slid on the table).
[[nodiscard]] std::expected<AxisFit, std::string> fitTurntableAxis(std::span<const TableView> views,
                                                                   const Target& target);

}  // namespace smx::calib
