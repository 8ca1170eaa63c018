#pragma once

#include <cstddef>
#include <cstdint>
#include <expected>
#include <memory>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/scan/points.hpp"
#include "smx/scan/range_view.hpp"
#include "smx/scan/registration.hpp"

// Live tracking of a hand-held scan (docs/tracking.md): each range frame is
// registered to the model built so far (frame-to-model point-to-plane ICP from a constant-velocity
// prediction); well-tracked frames are fused into it; when tracking is lost (a hand over the
// lens, a view away from the model) frames are not fused until one registers again, first from
// the predicted and last good poses, then by global alignment to the keyframes, each verified by
// ICP against the model. Host only.
namespace smx::scan {

struct TrackerOptions {
  int pixelStep = 2;        // depth images are read at every step-th pixel in x and y
  double minDepthM = 0.15;  // depths outside [min, max] are not the scanned object
  double maxDepthM = 1.5;
  double frameVoxelM = 0.002;  // the frame's cloud, registered to the model
  double modelVoxelM = 0.002;  // the fused model cloud (running mean per voxel)
  // Frame to model, coarse to fine: the coarse level catches a prediction off by a centimetre.
  IcpOptions icp{.levelVoxelsM = {0.008, 0.003},
                 .maxDistanceVoxels = 3.0,
                 .kernelVoxels = 2.0,
                 .iterationsPerLevel = 12};
  std::size_t minPoints = 300;  // fewer points with normals: lost (nothing in range)
  // Good: fused. Weak: tracked, not fused. Worse: lost. Fitness: share of the frame's points
  // with a model point within the finest ICP level's distance; RMSE along the model's normals.
  double goodFitness = 0.6;
  double goodRmseM = 0.001;
  double weakFitness = 0.35;
  double weakRmseM = 0.002;
  // A keyframe (cloud and pose) every this many degrees or metres of well-tracked motion.
  double keyframeDeg = 10.0;
  double keyframeM = 0.05;
  std::size_t maxKeyframes = 200;
  // Relocalisation: global alignment (FPFH + RANSAC) to at most this many keyframes nearest the
  // last good pose, on clouds at this voxel.
  std::size_t relocaliseKeyframes = 3;
  GlobalOptions global{.voxelM = 0.006, .minFitness = 0.3, .maxIterations = 20000};
  // The model seen from a pose: within this angle of cam0's axis and this distance.
  double viewHalfAngleDeg = 40.0;
  double viewMaxDistanceM = 1.5;
};

enum class TrackingState : std::uint8_t {
  kTracking,     // registered to the model from the prediction
  kLost,         // not registered: the pose is the last estimate, nothing fused
  kRelocalised,  // registered again after being lost
};

struct TrackQuality {
  double fitness = 0.0;       // share of the frame's points with a model point near
  double inlierRmseMm = 0.0;  // RMS distance of those pairs
  double score = 0.0;         // 0 … 1: fitness × (1 − rmse / weak rmse), clamped
  bool good = false;          // good enough to fuse
};

struct TrackResult {
  Pose pose = Pose::Identity();  // rig → model (the first frame's rig frame)
  TrackQuality quality;
  TrackingState state = TrackingState::kLost;
  bool fused = false;
  bool keyframe = false;   // kept as a keyframe
  std::size_t points = 0;  // the frame's points in range with normals
  std::string reason;      // why lost, for a status line ("12 points in range", ...)
};

class Tracker {
 public:
  // Errors: a rig without cameras, options out of range.
  [[nodiscard]] static std::expected<Tracker, std::string> create(
      const algo::Rig& rig, const TrackerOptions& options = {});
  Tracker(Tracker&&) noexcept;
  Tracker& operator=(Tracker&&) noexcept;
  Tracker(const Tracker&) = delete;
  Tracker& operator=(const Tracker&) = delete;
  ~Tracker();

  // One frame, in capture order. The first frame with enough points starts the model at the
  // identity pose.
  [[nodiscard]] TrackResult track(const RangeView& view);

  // The fused model (model frame): each voxel's mean point and normal.
  [[nodiscard]] Cloud model() const;
  [[nodiscard]] std::size_t keyframes() const;

 private:
  struct Impl;
  explicit Tracker(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace smx::scan
