#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

// A hand-held scan played by the simulated rig (scene.json "handheld", docs/scene-format.md): the
// rig orbits a point of the world along a smooth path, bobs slowly along the orbit axis and
// trembles with band-limited hand jitter; a hand may cover the lenses for a while. The world is
// the rig's frame on the smooth path at frame 0 (cam0's frame for the example rigs).
namespace smx::sim {

// A dark plane fixed to the rig in front of its lenses (a hand over them) for frames
// [fromFrame, fromFrame + frames).
struct HandheldOcclusion {
  int fromFrame = 0;
  int frames = 0;  // 0: no occlusion
  double distanceM = 0.1;
};

struct Handheld {
  Eigen::Vector3d centre{0.0, 0.0, 0.6};  // world point the rig orbits (and looks at)
  Eigen::Vector3d axis{0.0, -1.0, 0.0};   // orbit axis, world direction, unit
  double orbitDegPerFrame = 1.2;          // right-handed about axis
  double bobM = 0.0;                      // amplitude of the slow motion along the axis
  double bobPeriodFrames = 300.0;
  double jitterMm = 0.0;   // RMS length of the translation jitter
  double jitterDeg = 0.0;  // RMS angle of the rotation jitter
  double jitterHz = 2.0;   // highest jitter frequency
  double fps = 15.0;       // frames per second: relates frames to jitterHz
  std::uint32_t seed = 1;  // jitter frequencies and phases
  HandheldOcclusion occlusion;
};

// Sinusoids per jitter axis: enough that the jitter looks irregular and its RMS over a loop is
// close to the asked one.
inline constexpr int kHandheldJitterTerms = 4;

// The true pose of the rig (rig → world: X_world = T · X_rig) at a frame time, fractional within
// an exposure: smooth(t) · jitter(t), where smooth(t) turns by t · orbitDegPerFrame about the
// axis through the centre and then shifts by bobM · sin(2π t / bobPeriodFrames) along the axis,
// and jitter(t) (in the rig's frame) is a sum of kHandheldJitterTerms seeded sinusoids per axis
// with frequencies up to jitterHz: smooth in t, RMS jitterMm and jitterDeg over long times.
[[nodiscard]] Eigen::Isometry3d handheldRigPose(const Handheld& handheld, double frameTime);

// The jitter part alone (rig frame): handheldRigPose = smooth · handheldJitter.
[[nodiscard]] Eigen::Isometry3d handheldJitter(const Handheld& handheld, double frameTime);

// Whether the occluder covers the lenses at a frame time (that of the nearest whole frame).
[[nodiscard]] bool handheldOccluded(const Handheld& handheld, double frameTime);

}  // namespace smx::sim
