#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"

// What a scan is made of: range views of the rig (every camera's range image of one capture) and
// where the rig was when each was taken. Host only: registration, fusion and meshing never run on
// the board (docs/scanning.md).
namespace smx::scan {

// One camera's range image of a capture, as the device sent it.
struct CameraRange {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> depth;  // width × height, z in depthUnitM, 0 = no data
  // width × height RGB of the same camera with every projector off, row by row; empty if none
  // (a handheld scan has no such frame: its projectors never go off)
  std::vector<std::array<std::uint8_t, 3>> colour;
};

// One capture: every rig camera's range image (in the rig's camera order) and what is known of
// the rig's pose then.
struct RangeView {
  std::string id;  // a name ("00000", …), never a path
  std::vector<CameraRange> cameras;
  double depthUnitM = 1e-4;
  std::int64_t captureNs = 0;          // the device's clock, 0 when unknown
  std::optional<double> turntableDeg;  // the table's angle when captured (turntable scans)
};

// Rig → model: a point X in the rig's world frame (cam0's, as in rig.json) is at pose · X in the
// model's frame. The first view's pose is the identity unless a turntable places it.
using Pose = Eigen::Isometry3d;

// The turntable's axis of rotation in the rig's world frame: a unit direction and a point on it.
// A positive angle turns the table by the right-hand rule about `direction`.
struct TurntableAxis {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitY();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

}  // namespace smx::scan
