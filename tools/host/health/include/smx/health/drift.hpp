#pragma once

#include <array>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"

// A small pose change of one projector, in its own frame (x right, y down, z forward): what a
// knock or a warm mount does to a calibrated rig. The rotation turns about the projector's centre.
// Host code: the health check's attribution and its tests and figures.
namespace smx::health {

struct Drift {
  std::array<double, 3> shiftM{};       // projector frame
  std::array<double, 3> rotationRad{};  // rotation vector, projector frame
};

// The rig with projector `projector` moved by `drift`.
[[nodiscard]] algo::Rig withDrift(const algo::Rig& rig, int projector, const Drift& drift);

// The drifts the health check is specified to catch, for one projector and one camera of a rig:
// 1 mm along the camera–projector baseline and perpendicular to it towards the scene, and 0.2°
// about the stripe axis (in the projector's image plane) and about the optical axis.
struct NamedDrift {
  std::string name;
  Drift drift;
};
[[nodiscard]] std::vector<NamedDrift> specifiedDrifts(const algo::Rig& rig, int projector,
                                                      int camera = 0);

// Drifts at the check's limits, for the figures: 1 mm along the optical axis (about half the
// disagreement of the specified drifts) and 1 mm along the projector's stripes (none at all).
[[nodiscard]] std::vector<NamedDrift> limitDrifts(const algo::Rig& rig, int projector);

}  // namespace smx::health
