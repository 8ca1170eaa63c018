#pragma once

#include <vector>

#include "smx/sim/handheld.hpp"
#include "smx/sim/scene.hpp"

// The scene as the hand-held rig sees it. The renderer keeps the rig still (its cameras and
// projectors at their rig.json poses) and moves the world instead: an object whose world pose at
// time t is P is drawn at handheldRigPose(t)⁻¹ · P, which is the same picture, truth depth
// included, and composes with objects' own motion and with the exposure's time samples.
namespace smx::sim::detail {

class HandheldView {
 public:
  // Appends the occluder the scene asks for (a dark plane, "handheld_occluder") to `objects`;
  // `objects` must not be resized afterwards (the view remembers which one it is).
  HandheldView(const Handheld& handheld, std::vector<Object>& objects);

  // The pose in the rig's frame at time t (frames) of `object`, whose world pose then is `world`.
  [[nodiscard]] Pose seenFromRig(const Object& object, const Pose& world, double t) const;

 private:
  Handheld handheld_;
  const Object* occluder_ = nullptr;
};

}  // namespace smx::sim::detail
