#include "handheld_view.hpp"

namespace smx::sim::detail {
namespace {

// Wide enough to fill the view of any example rig's camera and projectors at the distances
// scene.json allows (a 2 m square at 0.1 m covers ±84°).
constexpr double kOccluderSideM = 2.0;
constexpr double kOccluderAlbedo = 0.05;  // a dark glove: no stripes worth decoding
// Out of the way when the hand is not there: behind the rig, where no camera or projector ray
// (forward from the rig) and no shadow ray (between the scene and a projector) reaches.
constexpr double kParkedZM = -1000.0;

}  // namespace

HandheldView::HandheldView(const Handheld& handheld, std::vector<Object>& objects)
    : handheld_(handheld) {
  if (handheld.occlusion.frames <= 0) {
    return;
  }
  Object occluder;
  occluder.name = "handheld_occluder";
  occluder.shape = Plane{kOccluderSideM, kOccluderSideM};
  occluder.albedo.rgb = Vec3::Constant(kOccluderAlbedo);
  objects.push_back(std::move(occluder));
  occluder_ = &objects.back();
}

Pose HandheldView::seenFromRig(const Object& object, const Pose& world, double t) const {
  if (&object == occluder_) {
    // Fixed to the rig, so already in its frame.
    Pose p;
    p.t =
        Vec3(0.0, 0.0, handheldOccluded(handheld_, t) ? handheld_.occlusion.distanceM : kParkedZM);
    return p;
  }
  const Eigen::Isometry3d worldToRig = handheldRigPose(handheld_, t).inverse();
  Pose p;
  p.R = worldToRig.linear() * world.R;
  p.t = worldToRig * world.t;
  p.scale = world.scale;
  return p;
}

}  // namespace smx::sim::detail
