#include "smx/scan/fuse.hpp"

#include <open3d/pipelines/registration/GlobalOptimization.h>
#include <open3d/pipelines/registration/PoseGraph.h>
#include <open3d/utility/Logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "smx/scan/model_cleanup.hpp"
#include "smx/scan/range_clean.hpp"
#include "smx/scan/table_crop.hpp"
#include "smx/scan/watertight.hpp"

namespace smx::scan {
namespace {

namespace reg = open3d::pipelines::registration;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string fixed(double v, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, v);
  return text;
}

// One registration between views: `source` onto `target`, in the rigs' frames.
struct Edge {
  std::size_t source = 0;
  std::size_t target = 0;
  bool loop = false;  // closes a loop or skips a view: Open3D may prune it
  Registration registration;
};

struct Placement {
  std::vector<Pose> poses;
  std::vector<bool> accepted;
  std::vector<double> fitness;
  std::vector<double> rmseM;
};

class Fuser {
 public:
  Fuser(const std::vector<RangeView>& views, const algo::Rig& rig, const FuseOptions& options)
      : views_(views), rig_(rig), options_(options) {}

  void say(const std::string& line) const {
    if (options_.progress) {
      options_.progress(line);
    }
  }

  void makeClouds() {
    const CloudOptions cloudOptions{.voxelM = options_.registrationVoxelM};
    clouds_.reserve(views_.size());
    for (const auto& view : views_) {
      clouds_.push_back(viewCloud(rig_, view, cloudOptions));
    }
    say("clouds of " + std::to_string(views_.size()) + " views at " +
        fixed(options_.registrationVoxelM * 1e3, 1) + " mm");
  }

  [[nodiscard]] IcpOptions icpOptions() const {
    const double v = options_.registrationVoxelM;
    return IcpOptions{.levelVoxelsM = {4 * v, 2 * v, v}};
  }

  // Sequential: each view registered to the last accepted one, starting from the last motion.
  Placement sequential() {
    Placement p = empty();
    std::size_t last = 0;
    Pose motion = Pose::Identity();  // last accepted view → the one before it
    p.accepted[0] = !clouds_[0].empty();
    p.fitness[0] = 1;
    for (std::size_t i = 1; i < views_.size(); ++i) {
      if (clouds_[i].empty() || clouds_[last].empty()) {
        p.poses[i] = p.poses[last];
        if (!p.accepted[last]) {
          last = i;
          p.accepted[i] = !clouds_[i].empty();
        }
        continue;
      }
      auto best = registerIcp(clouds_[i], clouds_[last], motion, icpOptions());
      if (best && best->fitness < options_.minFitness) {
        auto still = registerIcp(clouds_[i], clouds_[last], Pose::Identity(), icpOptions());
        if (still && still->fitness > best->fitness) {
          best = still;
        }
      }
      p.fitness[i] = best ? best->fitness : 0;
      p.rmseM[i] = best ? best->inlierRmseM : 0;
      p.poses[i] = p.poses[last] * (best ? best->pose : motion);
      if (best && best->fitness >= options_.minFitness) {
        p.accepted[i] = true;
        motion = best->pose;
        last = i;
      }
      say("view " + views_[i].id + ": fitness " + fixed(p.fitness[i], 2) + ", rmse " +
          fixed(p.rmseM[i] * 1e3, 3) + " mm");
    }
    return p;
  }

  // Initial poses refined: each view registered to its next two neighbours (and the ring closed
  // when `ring`), then, when `optimise`, a pose graph spreads the residuals so that the loop
  // closes. Without it the poses stay as given and the registrations only judge the overlap.
  Placement refined(std::vector<Pose> initial, bool ring, bool optimise, FuseReport& report) {
    Placement p = empty();
    p.poses = std::move(initial);
    const std::size_t n = views_.size();
    std::vector<Edge> edges;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t step = 1; step <= 2; ++step) {
        const std::size_t j = i + step;
        if (j >= n && (!ring || n < 2 * step + 1)) {
          continue;
        }
        const std::size_t target = j % n;
        if (clouds_[i].empty() || clouds_[target].empty()) {
          continue;
        }
        const Pose guess = p.poses[target].inverse() * p.poses[i];
        auto r = registerIcp(clouds_[i], clouds_[target], guess, icpOptions());
        if (!r) {
          continue;
        }
        say("view " + views_[i].id + " → " + views_[target].id + ": fitness " +
            fixed(r->fitness, 2) + ", rmse " + fixed(r->inlierRmseM * 1e3, 3) + " mm");
        for (const std::size_t v : {i, target}) {
          if (r->fitness > p.fitness[v]) {
            p.fitness[v] = r->fitness;
            p.rmseM[v] = r->inlierRmseM;
          }
        }
        edges.push_back({i, target, step > 1 || j >= n, *r});
      }
    }
    for (std::size_t v = 0; v < n; ++v) {
      p.accepted[v] = p.fitness[v] >= options_.minFitness;
    }
    // The loop's gap: the last view carried to the first through the chain, against their
    // direct registration, at the last view's centroid.
    const auto loopGap = [&](const std::vector<Pose>& poses) {
      for (const auto& e : edges) {
        if (e.source == n - 1 && e.target == 0 && !clouds_[n - 1].empty()) {
          Eigen::Vector3d c = Eigen::Vector3d::Zero();
          for (const auto& x : clouds_[n - 1].points) {
            c += x;
          }
          c /= static_cast<double>(clouds_[n - 1].size());
          return ((poses[0].inverse() * poses[n - 1]) * c - e.registration.pose * c).norm();
        }
      }
      return 0.0;
    };
    reg::PoseGraph graph;
    for (const auto& pose : p.poses) {
      graph.nodes_.emplace_back(pose.matrix());
    }
    for (const auto& e : edges) {
      if (e.registration.fitness >= options_.minFitness && p.accepted[e.source] &&
          p.accepted[e.target]) {
        graph.edges_.emplace_back(static_cast<int>(e.source), static_cast<int>(e.target),
                                  e.registration.pose.matrix(), e.registration.information, e.loop);
      }
    }
    const double before = loopGap(p.poses);
    if (optimise && !graph.edges_.empty()) {
      const reg::GlobalOptimizationOption option(2 * options_.registrationVoxelM, 0.25, 1.0, 0);
      reg::GlobalOptimization(graph, reg::GlobalOptimizationLevenbergMarquardt(),
                              reg::GlobalOptimizationConvergenceCriteria(), option);
      for (std::size_t v = 0; v < n; ++v) {
        p.poses[v] = Pose(Eigen::Matrix4d(graph.nodes_[v].pose_));
      }
    }
    report.loopClosureM = loopGap(p.poses);
    if (ring) {
      say(optimise ? "loop gap " + fixed(before * 1e3, 3) + " mm before the pose graph, " +
                         fixed(report.loopClosureM * 1e3, 3) + " mm after"
                   : "loop gap " + fixed(before * 1e3, 3) + " mm with the table's angles");
    }
    return p;
  }

  [[nodiscard]] Placement empty() const {
    Placement p;
    p.poses.assign(views_.size(), Pose::Identity());
    p.accepted.assign(views_.size(), false);
    p.fitness.assign(views_.size(), 0.0);
    p.rmseM.assign(views_.size(), 0.0);
    return p;
  }

 private:
  const std::vector<RangeView>& views_;
  const algo::Rig& rig_;
  const FuseOptions& options_;
  std::vector<Cloud> clouds_;
};

}  // namespace

Pose turntablePose(const TurntableAxis& axis, double deg) {
  const double rad = -deg * std::numbers::pi / 180.0;
  return Eigen::Translation3d(axis.point) * Eigen::AngleAxisd(rad, axis.direction.normalized()) *
         Eigen::Translation3d(-axis.point);
}

std::vector<RangeView> viewsForFusion(const std::vector<RangeView>& input, const algo::Rig& rig,
                                      const FuseOptions& options) {
  std::vector<RangeView> views = input;
  const bool turntable =
      options.axis && options.tableRadiusM > 0 && !input.empty() &&
      std::ranges::all_of(input, [](const RangeView& v) { return v.turntableDeg.has_value(); });
  for (auto& view : views) {
    if (turntable) {
      keepOnTable(view, rig, *options.axis, options.tableRadiusM);
    }
    cleanForFusion(view, rig, options.clean);
  }
  return views;
}

std::expected<FuseResult, FuseError> fuseViews(const std::vector<RangeView>& input,
                                               const algo::Rig& rig,
                                               const std::vector<std::optional<Pose>>& givenPoses,
                                               const FuseOptions& options) {
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
  std::vector<RangeView> views = viewsForFusion(input, rig, options);
  FuseReport report;
  const auto failWith = [&report](std::string message) {
    return std::unexpected(FuseError{std::move(message), report});
  };
  if (!givenPoses.empty() && givenPoses.size() != views.size()) {
    return failWith("poses are given for " + std::to_string(givenPoses.size()) + " of " +
                    std::to_string(views.size()) + " views");
  }
  if (!(options.voxelM > 0) || !(options.registrationVoxelM > 0)) {
    return failWith("the voxel sizes must be positive");
  }
  if (views.size() < 2) {
    return failWith("fusing needs at least 2 views, got " + std::to_string(views.size()));
  }
  auto tsdf = Tsdf::create(rig, {.voxelM = options.voxelM, .truncationM = 4 * options.voxelM});
  if (!tsdf) {
    return failWith(tsdf.error());
  }

  auto start = Clock::now();
  Fuser fuser(views, rig, options);
  fuser.makeClouds();
  const bool allGiven = !givenPoses.empty() && std::ranges::all_of(givenPoses, [](const auto& p) {
    return p.has_value();
  });
  const bool allAngles =
      std::ranges::all_of(views, [](const RangeView& v) { return v.turntableDeg.has_value(); });
  Placement placement;
  if (allGiven) {
    std::vector<Pose> given;
    given.reserve(givenPoses.size());
    for (const auto& p : givenPoses) {
      given.push_back(p.value_or(Pose::Identity()));  // all set: allGiven
    }
    report.placement = "given";
    if (options.refine) {
      placement = fuser.refined(given, false, true, report);
    } else {
      placement = fuser.empty();
      placement.poses = given;
      placement.accepted.assign(views.size(), true);
      placement.fitness.assign(views.size(), 1.0);
    }
  } else if (allAngles && options.axis) {
    report.placement = "turntable";
    const TurntableAxis& axis = *options.axis;  // NOLINT(bugprone-unchecked-optional-access)
    std::vector<Pose> initial;
    initial.reserve(views.size());
    for (const auto& v : views) {
      initial.push_back(turntablePose(axis, v.turntableDeg.value_or(0.0)));  // all set: allAngles
    }
    // A ring only when the views go round: the first and last overlap.
    const double span = std::abs(views.back().turntableDeg.value_or(0.0) -
                                 views.front().turntableDeg.value_or(0.0));
    const double step = span / static_cast<double>(views.size() - 1);
    const bool ring = span + 1.5 * step >= 360.0;
    placement = fuser.refined(initial, ring, options.refine, report);
  } else {
    report.placement = "sequential";
    if (allAngles) {
      fuser.say("views have turntable angles but no axis is known: placed by sequential ICP");
    }
    placement = fuser.sequential();
  }
  report.registrationS = secondsSince(start);

  start = Clock::now();
  for (std::size_t i = 0; i < views.size(); ++i) {
    ViewReport view{.id = views[i].id,
                    .fused = placement.accepted[i],
                    .reason = {},
                    .fitness = placement.fitness[i],
                    .rmseM = placement.rmseM[i],
                    .pose = placement.poses[i]};
    if (view.fused) {
      if (auto ok = tsdf->integrate(views[i], placement.poses[i]); !ok) {
        view.fused = false;
        view.reason = ok.error();
      }
    } else {
      view.reason = "view " + view.id + " does not overlap the others (fitness " +
                    fixed(view.fitness, 2) + "): not fused";
      fuser.say(view.reason);
    }
    report.fusedViews += view.fused ? 1 : 0;
    report.views.push_back(std::move(view));
  }
  report.fusionS = secondsSince(start);
  if (report.fusedViews < 2) {
    return failWith("only " + std::to_string(report.fusedViews) + " of " +
                    std::to_string(views.size()) +
                    " views overlap enough to be fused; at least 2 are needed");
  }
  fuser.say("fused " + std::to_string(report.fusedViews) + " of " + std::to_string(views.size()) +
            " views");

  start = Clock::now();
  FuseResult result;
  result.model = tsdf->extractCloud();
  result.mesh = tsdf->extractMesh();
  if (options.minPieceShare > 0) {
    const auto cleanup =
        removeLoosePieces(result.mesh, result.model, options.minPieceShare, options.voxelM);
    report.loosePiecesRemoved = cleanup.piecesRemoved;
    if (cleanup.piecesRemoved > 0) {
      fuser.say("removed " + std::to_string(cleanup.piecesRemoved) + " loose pieces (" +
                std::to_string(cleanup.trianglesRemoved) + " triangles) apart from the model");
    }
  }
  if (options.watertight) {
    auto mesh =
        watertightMesh(result.model, {.voxelM = options.voxelM, .holeMaxM = options.holeMaxM});
    if (!mesh) {
      return failWith(mesh.error());
    }
    result.mesh = std::move(*mesh);
  }
  report.meshingS = secondsSince(start);
  if (!result.model.empty()) {
    report.extentMin = result.model.points.front();
    report.extentMax = result.model.points.front();
    for (const auto& x : result.model.points) {
      report.extentMin = report.extentMin.cwiseMin(x);
      report.extentMax = report.extentMax.cwiseMax(x);
    }
  }
  result.poses = placement.poses;
  result.report = std::move(report);
  return result;
}

}  // namespace smx::scan
