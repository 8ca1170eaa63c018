#include "smx/scan/tracker.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <utility>

#include "frame_cloud.hpp"
#include "plane_fit.hpp"
#include "smx/algo/lens.hpp"
#include "voxel_cloud.hpp"

namespace smx::scan {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

double angleOf(const Pose& pose) {
  return Eigen::AngleAxisd(pose.linear()).angle();
}

// The motion `delta` repeated `times` times (a screw scaled: angle and translation alike); good
// for the small frame-to-frame motions of a hand.
Pose repeated(const Pose& delta, double times) {
  const Eigen::AngleAxisd turn(delta.linear());
  Pose out = Pose::Identity();
  out.linear() = Eigen::AngleAxisd(turn.angle() * times, turn.axis()).toRotationMatrix();
  out.translation() = delta.translation() * times;
  return out;
}

std::optional<std::string> optionsProblem(const TrackerOptions& o) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (o.pixelStep < 1 || o.pixelStep > 16) {
    return "pixelStep must be from 1 to 16";
  }
  if (!positive(o.minDepthM) || !positive(o.maxDepthM) || o.maxDepthM <= o.minDepthM) {
    return "the depth range must be positive and not empty";
  }
  if (!positive(o.frameVoxelM) || !positive(o.modelVoxelM) || !positive(o.keyframeDeg) ||
      !positive(o.keyframeM) || !positive(o.viewHalfAngleDeg) || o.viewHalfAngleDeg >= 90 ||
      !positive(o.viewMaxDistanceM)) {
    return "voxels, keyframe spacings and the view limits must be positive";
  }
  if (!(o.weakFitness <= o.goodFitness) || !(o.goodRmseM <= o.weakRmseM) ||
      !positive(o.goodRmseM)) {
    return "the weak thresholds must be looser than the good ones";
  }
  return std::nullopt;
}

}  // namespace

struct Tracker::Impl {
  struct Keyframe {
    Cloud cloud;  // rig frame
    Pose pose;
  };

  Impl(const algo::Rig& r, const TrackerOptions& o)
      : rig(r),
        options(o),
        frames(r, {.step = o.pixelStep, .minDepthM = o.minDepthM, .maxDepthM = o.maxDepthM}),
        model(o.modelVoxelM) {
    const auto& cam0 = rig.cameras.front();
    const auto c = algo::lens::centre(cam0);
    centre = {c[0], c[1], c[2]};
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> rotation(cam0.R.data());
    forward = rotation.transpose() * Eigen::Vector3d::UnitZ();
  }

  TrackResult track(const RangeView& view);
  [[nodiscard]] Cloud frameCloud(const RangeView& view, std::size_t& inRange) const;
  [[nodiscard]] std::optional<Registration> toModel(const Cloud& frame, const Pose& initial) const;
  [[nodiscard]] TrackQuality quality(const Registration& r) const;
  [[nodiscard]] bool weak(const Registration& r) const {
    return r.fitness >= options.weakFitness && r.inlierRmseM <= options.weakRmseM;
  }
  std::optional<Registration> relocalise(const Cloud& frame);
  void accept(const Cloud& frame, const Registration& r, TrackResult& out);

  algo::Rig rig;
  TrackerOptions options;
  detail::FrameCloud frames;
  detail::VoxelCloud model;
  Eigen::Vector3d centre;   // cam0's centre, rig frame
  Eigen::Vector3d forward;  // cam0's axis, rig frame
  std::vector<Keyframe> keyframes;
  bool started = false;
  bool lost = false;
  Pose pose = Pose::Identity();      // the last frame's estimate
  Pose lastGood = Pose::Identity();  // the last registered frame's pose
  Pose velocity = Pose::Identity();  // frame-to-frame motion, rig frame: next = pose · velocity
  int sinceGood = 0;                 // frames since the last registered one
};

Cloud Tracker::Impl::frameCloud(const RangeView& view, std::size_t& inRange) const {
  const Cloud all = frames.points(view);
  inRange = all.size();
  detail::VoxelCloud grid(options.frameVoxelM);
  grid.add(all);
  return grid.cloud();
}

std::optional<Registration> Tracker::Impl::toModel(const Cloud& frame, const Pose& initial) const {
  const Cloud target = model.visible(initial * centre, initial.linear() * forward,
                                     options.viewHalfAngleDeg * kDeg, options.viewMaxDistanceM);
  if (target.size() < options.minPoints) {
    return std::nullopt;
  }
  auto r = registerIcp(frame, target, initial, options.icp);
  if (!r) {
    return std::nullopt;
  }
  // Judged at the finest level's correspondence distance, along the model's normals.
  const detail::PlaneFit fit = detail::planeFit(
      frame, target, r->pose, options.icp.maxDistanceVoxels * options.icp.levelVoxelsM.back());
  r->fitness = fit.fitness;
  r->inlierRmseM = fit.rmseM;
  return *r;
}

TrackQuality Tracker::Impl::quality(const Registration& r) const {
  TrackQuality q;
  q.fitness = r.fitness;
  q.inlierRmseMm = r.inlierRmseM * 1e3;
  q.score = std::clamp(r.fitness * (1.0 - r.inlierRmseM / options.weakRmseM), 0.0, 1.0);
  q.good = r.fitness >= options.goodFitness && r.inlierRmseM <= options.goodRmseM;
  return q;
}

// Tries the pose the motion so far predicts, the last good pose, then global alignment to the
// keyframes nearest the last good pose; each must register to the model as a good frame does,
// so a resumed track agrees with the model (no jump).
std::optional<Registration> Tracker::Impl::relocalise(const Cloud& frame) {
  const std::vector<Pose> guesses = {lastGood * repeated(velocity, sinceGood), lastGood};
  for (const Pose& guess : guesses) {
    if (auto r = toModel(frame, guess); r && quality(*r).good) {
      return r;
    }
  }
  std::vector<const Keyframe*> nearest;
  nearest.reserve(keyframes.size());
  for (const auto& k : keyframes) {
    nearest.push_back(&k);
  }
  const auto distance = [&](const Keyframe* k) {
    const Pose d = lastGood.inverse() * k->pose;
    return d.translation().norm() + 0.1 * angleOf(d);  // 10 cm per radian
  };
  std::ranges::sort(nearest, {}, distance);
  nearest.resize(std::min(nearest.size(), options.relocaliseKeyframes));
  for (const Keyframe* k : nearest) {
    const auto aligned = alignGlobal(frame, k->cloud, options.global, options.icp);
    if (!aligned) {
      continue;
    }
    if (auto r = toModel(frame, k->pose * aligned->pose); r && quality(*r).good) {
      return r;
    }
  }
  return std::nullopt;
}

void Tracker::Impl::accept(const Cloud& frame, const Registration& r, TrackResult& out) {
  out.pose = r.pose;
  out.quality = quality(r);
  // Per frame: the motion since the last registered frame, spread over the frames between.
  velocity = repeated(lastGood.inverse() * r.pose, 1.0 / std::max(sinceGood, 1));
  pose = r.pose;
  lastGood = r.pose;
  sinceGood = 0;
  lost = false;
  if (!out.quality.good) {
    return;
  }
  model.add(transformed(frame, r.pose));
  out.fused = true;
  const Pose fromKey =
      keyframes.empty() ? Pose::Identity() : keyframes.back().pose.inverse() * r.pose;
  if (keyframes.empty() || angleOf(fromKey) > options.keyframeDeg * kDeg ||
      fromKey.translation().norm() > options.keyframeM) {
    if (keyframes.size() >= options.maxKeyframes) {
      keyframes.erase(keyframes.begin());
    }
    keyframes.push_back({frame, r.pose});
    out.keyframe = true;
  }
}

TrackResult Tracker::Impl::track(const RangeView& view) {
  TrackResult out;
  std::size_t inRange = 0;
  const Cloud frame = frameCloud(view, inRange);
  out.points = inRange;
  ++sinceGood;
  const Pose predicted = lastGood * repeated(velocity, sinceGood);
  out.pose = predicted;
  if (inRange < options.minPoints || frame.size() < options.minPoints) {
    out.reason = std::to_string(inRange) + " points in range";
    lost = lost || started;
    pose = predicted;
    return out;
  }
  if (!started) {
    started = true;
    Registration first;
    first.fitness = 1.0;
    accept(frame, first, out);
    out.state = TrackingState::kTracking;
    return out;
  }
  if (!lost) {
    const auto r = toModel(frame, predicted);
    if (r && weak(*r)) {
      accept(frame, *r, out);
      out.state = TrackingState::kTracking;
      return out;
    }
    if (r) {
      out.quality = quality(*r);
    }
    lost = true;
  }
  if (auto r = relocalise(frame)) {
    accept(frame, *r, out);
    out.state = TrackingState::kRelocalised;
    return out;
  }
  out.reason = "does not register to the model";
  pose = predicted;
  return out;
}

std::expected<Tracker, std::string> Tracker::create(const algo::Rig& rig,
                                                    const TrackerOptions& options) {
  if (rig.cameras.empty()) {
    return std::unexpected("the rig has no camera to track with");
  }
  if (auto problem = optionsProblem(options)) {
    return std::unexpected("tracker options: " + *problem);
  }
  return Tracker(std::make_unique<Impl>(rig, options));
}

Tracker::Tracker(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Tracker::Tracker(Tracker&&) noexcept = default;
Tracker& Tracker::operator=(Tracker&&) noexcept = default;
Tracker::~Tracker() = default;

TrackResult Tracker::track(const RangeView& view) {
  return impl_->track(view);
}

Cloud Tracker::model() const {
  return impl_->model.cloud();
}

std::size_t Tracker::keyframes() const {
  return impl_->keyframes.size();
}

}  // namespace smx::scan
