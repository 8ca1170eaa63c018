#pragma once

#include "smx/algo/rig.hpp"
#include "smx/health/camera_depths.hpp"
#include "smx/health/disagreement.hpp"

// A projector-free reference (docs/health-check.md): one projector's depths from a second camera,
// carried through the world frame into the first camera's image and compared with the first
// camera's depths of the same projector. Both cameras triangulate the same stripe planes; when the
// rig's plane of a stripe is wrong, the two cameras' rays meet it at different points, so a moved
// projector disagrees with itself across the cameras. Host code.
namespace smx::health {

// Per pixel of `first`: its depth − the second camera's point's depth in its frame, mm, where
// the second camera's point lands between four first-camera pixels that have depth.
[[nodiscard]] DisagreementField crossCameraField(const algo::Rig& rig, const CameraDepths& first,
                                                 const CameraDepths& second, int projector);

}  // namespace smx::health
