#include "smx/scan_eval/handheld_eval.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "decoded_range.hpp"
#include "smx/eval/sim_frame.hpp"
#include "smx/scan/fuse.hpp"
#include "smx/scan/tracker.hpp"
#include "smx/sim/handheld.hpp"
#include "smx/text/printf_text.hpp"
#include "truth_surface.hpp"

namespace smx::scan_eval {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kDegPerRad = 180.0 / std::numbers::pi;

struct PoseError {
  double mm = 0.0;
  double deg = 0.0;
};

PoseError poseError(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  const Eigen::Isometry3d delta = truth.inverse() * estimate;
  return {.mm = delta.translation().norm() * 1000.0,
          .deg = Eigen::AngleAxisd(delta.rotation()).angle() * kDegPerRad};
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) {
    return 0.0;
  }
  const auto k = static_cast<std::size_t>(p * static_cast<double>(values.size() - 1));
  std::ranges::nth_element(values, values.begin() + static_cast<std::ptrdiff_t>(k));
  return values[k];
}

}  // namespace

HandheldEvalResult runHandheldEval(const HandheldEvalOptions& options) {
  const auto say = [&](const std::string& line) {
    if (options.progress) {
      options.progress(line);
    }
  };
  sim::Scene scene = eval::loadNamedScene(options.scene);
  if (!scene.handheld) {
    throw std::runtime_error("scene " + options.scene + " has no hand-held trajectory");
  }
  if (options.supersampling > 0) {
    scene.supersampling = options.supersampling;
  }
  if (options.realism) {
    detail::addRealism(scene);
  }
  const sim::Handheld& hand = *scene.handheld;
  const algo::Rig rig = eval::loadExampleRig(options.rigFile);
  auto tracker = scan::Tracker::create(rig);
  if (!tracker) {
    throw std::runtime_error("tracker: " + tracker.error());
  }
  // The model's frame is the rig's at frame 0; the truth of frame f in it: T(0)⁻¹·T(f).
  const Eigen::Isometry3d first = sim::handheldRigPose(hand, 0.0);
  HandheldEvalResult result;
  result.scene = options.scene;
  result.frames = options.frames;
  std::vector<scan::RangeView> fusedViews;
  std::vector<scan::Pose> fusedPoses;
  std::vector<double> trackMs;
  double sumMm2 = 0.0;
  double sumDeg2 = 0.0;
  bool wasOccluded = false;
  for (int f = 0; f < options.frames; ++f) {
    scan::RangeView view;
    view.id = text::printfText("%05d", f);
    for (int c = 0; c < static_cast<int>(rig.cameras.size()); ++c) {
      eval::SimRequest request;
      request.camera = c;
      request.frame = f;
      request.seed = options.seed;
      view.cameras.push_back(detail::decoded(eval::renderSimFrame(rig, scene, request), c));
    }
    const auto start = Clock::now();
    const scan::TrackResult tracked = tracker->track(view);
    trackMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());

    const bool occluded = sim::handheldOccluded(hand, f);
    result.occluded += occluded ? 1 : 0;
    result.occludedFused += occluded && tracked.fused ? 1 : 0;
    const Eigen::Isometry3d truth = first.inverse() * sim::handheldRigPose(hand, f);
    const PoseError error = poseError(tracked.pose, truth);
    if (tracked.state == scan::TrackingState::kLost) {
      ++result.lost;
    } else {
      ++result.tracked;
      sumMm2 += error.mm * error.mm;
      sumDeg2 += error.deg * error.deg;
      if (wasOccluded && !occluded && result.resumeFrame < 0) {
        result.resumeFrame = f;
        result.resumeErrorMm = error.mm;
      }
    }
    wasOccluded = wasOccluded || occluded;
    if (f == options.frames - 1) {
      result.driftMm = error.mm;
      result.driftDeg = error.deg;
    }
    if (tracked.fused) {
      ++result.fused;
      fusedPoses.push_back(tracked.pose);
      fusedViews.push_back(std::move(view));
    }
    if (f % 10 == 0 || occluded) {
      say(text::printfText("  frame %d: %s, %.2f mm / %.3f° from the truth, %.0f ms", f,
                           tracked.state == scan::TrackingState::kLost ? "lost" : "tracked",
                           error.mm, error.deg, trackMs.back()));
    }
  }
  if (result.tracked > 0) {
    result.trajectoryRmsMm = std::sqrt(sumMm2 / result.tracked);
    result.trajectoryRmsDeg = std::sqrt(sumDeg2 / result.tracked);
  }
  double sumMs = 0.0;
  for (const double ms : trackMs) {
    sumMs += ms;
  }
  result.trackMsMean = trackMs.empty() ? 0.0 : sumMs / static_cast<double>(trackMs.size());
  result.trackMsP95 = percentile(trackMs, 0.95);

  // The fused frames at their tracked poses, fused as the scan command's fuse step does.
  const std::vector<std::optional<scan::Pose>> given(fusedPoses.begin(), fusedPoses.end());
  scan::FuseOptions fuse;
  fuse.voxelM = options.voxelM;
  auto fused = scan::fuseViews(fusedViews, rig, given, fuse);
  if (!fused) {
    throw std::runtime_error("fusing the tracked frames: " + fused.error().message);
  }
  const scan::Mesh& mesh = fused->mesh;
  open3d::geometry::TriangleMesh truth;
  for (const auto& object : scene.objects) {
    truth += detail::objectSurface(object, first.inverse());
  }
  const auto distance = detail::distancesToSurface(mesh.vertices, truth);
  result.meshMeanMm = distance.meanMm;
  result.meshP95Mm = distance.p95Mm;
  return result;
}

}  // namespace smx::scan_eval
