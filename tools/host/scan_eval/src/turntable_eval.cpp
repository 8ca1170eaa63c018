#include "smx/scan_eval/turntable_eval.hpp"

#include <open3d/Open3D.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <variant>

#include "decoded_range.hpp"
#include "smx/algo/lens.hpp"
#include "smx/algo/range_image.hpp"
#include "smx/eval/sim_frame.hpp"
#include "smx/scan/fuse.hpp"
#include "smx/text/printf_text.hpp"
#include "truth_surface.hpp"

namespace smx::scan_eval {

namespace {

namespace lens = algo::lens;
using Clock = std::chrono::steady_clock;
using Vec3 = Eigen::Vector3d;

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
// A true surface point counts as seen when the rendered truth depth at its pixel is within this
// of its own depth, and as covered when a fused vertex lies within kCoveredM.
constexpr double kVisibleM = 0.002;
constexpr double kCoveredM = 0.001;
constexpr int kSurfaceSamples = 200000;
// Surface some view sees within this of head-on is well posed for stripes; beyond it they
// narrow in the camera towards the grazing limit.
constexpr double kWellSeenDeg = 60.0;

double seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

const sim::TurntableMount& mountOf(const sim::Scene& scene) {
  if (!scene.turntable) {
    throw std::runtime_error("the scene has no turntable");
  }
  return *scene.turntable;
}

// The turntable's rotation by `deg`.
Eigen::Matrix3d turn(const sim::TurntableMount& mount, double deg) {
  return Eigen::Matrix3d(Eigen::AngleAxisd(deg * kRadPerDeg, mount.axis.normalized()));
}

// The scene with its table turned by `deg`: objects on it are turned about the table's line.
sim::Scene turned(const sim::Scene& scene, double deg) {
  const auto& mount = mountOf(scene);
  const Eigen::Matrix3d q = turn(mount, deg);
  sim::Scene out = scene;
  for (auto& object : out.objects) {
    if (object.onTurntable) {
      object.pose.R = q * object.pose.R;
      object.pose.t = q * (object.pose.t - mount.pivot) + mount.pivot;
    }
  }
  return out;
}

// The objects standing on the table, at angle 0: the model's frame. `scannedOnly`: only the
// meshes among them, the scanned object (a primitive on the table is the platter, a fixture).
open3d::geometry::TriangleMesh trueSurface(const sim::Scene& scene, bool scannedOnly) {
  open3d::geometry::TriangleMesh all;
  for (const auto& object : scene.objects) {
    if (object.onTurntable && (!scannedOnly || std::holds_alternative<sim::Mesh>(object.shape))) {
      all += detail::objectSurface(object);
    }
  }
  if (all.triangles_.empty()) {
    throw std::runtime_error("no object stands on the scene's turntable");
  }
  return all;
}

struct Projected {
  int x = 0;
  int y = 0;
  Vec3 world = Vec3::Zero();   // the point with the table turned
  Vec3 device = Vec3::Zero();  // the same in the camera's frame
};

Vec3 inDevice(const algo::Camera& camera, const Vec3& w) {
  const auto d = lens::toDevice(camera, {w.x(), w.y(), w.z()});
  return {d[0], d[1], d[2]};
}

// Where the model-frame point `p` falls in `camera` with the table turned by `deg`.
std::optional<Projected> project(const algo::Camera& camera, const sim::TurntableMount& mount,
                                 double deg, const Vec3& p) {
  const Vec3 w = turn(mount, deg) * (p - mount.pivot) + mount.pivot;
  const auto uv = lens::project(camera, {w.x(), w.y(), w.z()});
  if (!uv) {
    return std::nullopt;
  }
  const int x = static_cast<int>(std::lround(uv->x));
  const int y = static_cast<int>(std::lround(uv->y));
  if (x < 0 || y < 0 || x >= camera.width || y >= camera.height) {
    return std::nullopt;
  }
  return Projected{.x = x, .y = y, .world = w, .device = inDevice(camera, w)};
}

// For each sample (model frame, with its normal) that camera `camera` sees lit in `frame`,
// rendered with the table at `deg`: the largest |cos| so far between its normal and a seeing
// camera's ray (1: head-on). Samples no view has seen stay at -1.
void markVisible(const eval::SimFrame& frame, int camera, const sim::Scene& scene, double deg,
                 const open3d::geometry::PointCloud& samples, std::vector<double>& bestCos) {
  const auto& device = frame.rig.cameras.at(static_cast<std::size_t>(camera));
  const auto& mount = mountOf(scene);
  const Eigen::Matrix3d q = turn(mount, deg);
  for (std::size_t i = 0; i < samples.points_.size(); ++i) {
    const auto at = project(device, mount, deg, samples.points_[i]);
    if (!at) {
      continue;
    }
    const double truth = frame.depth.at(at->x, at->y);
    bool lit = false;
    for (const auto& mask : frame.lit) {
      lit = lit || mask.at(at->x, at->y) != 0;
    }
    if (!lit || !std::isfinite(truth) || std::abs(at->device.z() - truth) >= kVisibleM) {
      continue;
    }
    const Vec3 normal = inDevice(device, at->world + q * samples.normals_[i]) - at->device;
    const double cos = std::abs(normal.normalized().dot(at->device.normalized()));
    bestCos[i] = std::max(bestCos[i], cos);
  }
}

// Whether some camera of some view has depth within kVisibleM of the model-frame point `p`.
bool inSomeView(const std::vector<scan::RangeView>& views, const algo::Rig& rig,
                const sim::TurntableMount& mount, const Vec3& p) {
  for (const auto& view : views) {
    for (std::size_t c = 0; c < view.cameras.size() && c < rig.cameras.size(); ++c) {
      const auto& range = view.cameras[c];
      const auto at = project(rig.cameras[c], mount, view.turntableDeg.value_or(0.0), p);
      if (!at || range.depth.empty()) {
        continue;
      }
      const std::uint16_t z =
          range.depth[static_cast<std::size_t>(at->y) * static_cast<std::size_t>(range.width) +
                      static_cast<std::size_t>(at->x)];
      if (z != 0 && std::abs(z * view.depthUnitM - at->device.z()) < kVisibleM) {
        return true;
      }
    }
  }
  return false;
}

struct Measured {
  double fuseS = 0.0;
  int fusedViews = 0;
  double loopClosureMm = 0.0;
  std::size_t meshVertices = 0;
  MarginResult margin;
  std::vector<char> covered;  // per seen sample: the mesh within kCoveredM
};

// `views` fused with `fuse`, the mesh against the true surface and the seen samples.
Measured fuseAndMeasure(const std::vector<scan::RangeView>& views, const algo::Rig& rig,
                        const scan::FuseOptions& fuse, const open3d::geometry::TriangleMesh& truth,
                        const std::vector<Vec3>& seenSamples) {
  Measured m;
  const auto fuseStart = Clock::now();
  auto fused = scan::fuseViews(views, rig, {}, fuse);
  m.fuseS = seconds(fuseStart);
  if (!fused) {
    throw std::runtime_error("fusing the views: " + fused.error().message);
  }
  m.fusedViews = static_cast<int>(fused->report.fusedViews);
  m.loopClosureMm = fused->report.loopClosureM * 1000.0;
  const auto& vertices = fused->mesh.vertices;
  m.meshVertices = vertices.size();
  if (vertices.empty()) {
    throw std::runtime_error("the fused mesh is empty");
  }
  const auto distance = detail::distancesToSurface(vertices, truth);
  open3d::geometry::TriangleMesh fusedMesh;
  fusedMesh.vertices_ = vertices;
  fusedMesh.triangles_ = fused->mesh.triangles;
  m.covered = detail::withinMask(seenSamples, fusedMesh, kCoveredM);
  const auto covered = static_cast<double>(std::ranges::count(m.covered, 1));
  m.margin = MarginResult{
      .edgePx = fuse.clean.edgePx,
      .meanMm = distance.meanMm,
      .p95Mm = distance.p95Mm,
      .coverage = seenSamples.empty() ? 0.0 : covered / static_cast<double>(seenSamples.size())};
  return m;
}

}  // namespace

TurntableEvalResult runTurntableEval(const TurntableEvalOptions& options) {
  const auto say = [&](const std::string& line) {
    if (options.progress) {
      options.progress(line);
    }
  };
  sim::Scene scene = eval::loadNamedScene(options.scene);
  if (options.supersampling > 0) {
    scene.supersampling = options.supersampling;
  }
  if (options.realism) {
    detail::addRealism(scene);
  }
  algo::Rig rig = eval::loadExampleRig(options.rigFile);
  const auto& mount = mountOf(scene);
  rig.turntable = algo::TurntableAxis{.axis = {mount.axis.x(), mount.axis.y(), mount.axis.z()},
                                      .point = {mount.pivot.x(), mount.pivot.y(), mount.pivot.z()}};

  // Distances to everything on the table; coverage of the scanned object.
  const open3d::geometry::TriangleMesh truth = trueSurface(scene, false);
  open3d::geometry::TriangleMesh scanned = trueSurface(scene, true);
  scanned.ComputeTriangleNormals();
  const auto sampled = scanned.SamplePointsUniformly(kSurfaceSamples, true);
  const std::vector<Vec3>& samples = sampled->points_;
  if (sampled->normals_.size() != samples.size()) {
    throw std::runtime_error("the true surface's samples have no normals");
  }
  std::vector<double> bestCos(samples.size(), -1.0);

  TurntableEvalResult result;
  result.scene = options.scene;
  result.rigFile = options.rigFile;
  result.views = options.views;
  std::vector<scan::RangeView> views;
  const auto decodeStart = Clock::now();
  for (int k = 0; k < options.views; ++k) {
    const double deg = 360.0 * k / options.views;
    const sim::Scene at = turned(scene, deg);
    scan::RangeView view;
    view.id = text::printfText("%03d", k);
    view.turntableDeg = deg;
    view.depthUnitM = algo::kDefaultDepthUnitM;
    for (int c = 0; c < static_cast<int>(rig.cameras.size()); ++c) {
      eval::SimRequest request;
      request.camera = c;
      request.seed = options.seed + static_cast<std::uint64_t>(k);
      const eval::SimFrame frame = eval::renderSimFrame(rig, at, request);
      view.cameras.push_back(detail::decoded(frame, c));
      markVisible(frame, c, scene, deg, *sampled, bestCos);
    }
    views.push_back(std::move(view));
    say(text::printfText("  view %d/%d at %.1f° rendered and decoded", k + 1, options.views, deg));
  }
  result.decodeS = seconds(decodeStart);

  scan::FuseOptions fuse;
  fuse.voxelM = options.voxelM;
  fuse.axis = scan::TurntableAxis{.direction = mount.axis.normalized(), .point = mount.pivot};
  fuse.tableRadiusM = options.tableRadiusM;
  std::vector<Vec3> seenSamples;
  std::vector<char> wellSeen;  // per seen sample: some view within kWellSeenDeg of head-on
  const double wellSeenCos = std::cos(kWellSeenDeg * kRadPerDeg);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (bestCos[i] >= 0.0) {
      seenSamples.push_back(samples[i]);
      wellSeen.push_back(static_cast<char>(bestCos[i] >= wellSeenCos));
    }
  }
  const std::size_t visible = seenSamples.size();
  const Measured measured = fuseAndMeasure(views, rig, fuse, truth, seenSamples);
  result.fuseS = measured.fuseS;
  result.fusedViews = measured.fusedViews;
  result.loopClosureMm = measured.loopClosureMm;
  result.meshVertices = measured.meshVertices;
  result.meanMm = measured.margin.meanMm;
  result.p95Mm = measured.margin.p95Mm;
  result.coverage = measured.margin.coverage;
  result.margins.push_back(measured.margin);
  const auto& covered = measured.covered;

  // Where the rest was lost: the views as decoded, and as the fusion took them.
  const std::vector<scan::RangeView> cleaned = scan::viewsForFusion(views, rig, fuse);
  std::size_t undecoded = 0;
  std::size_t removed = 0;
  std::size_t unmeshed = 0;
  for (std::size_t i = 0; i < visible; ++i) {
    if (covered[i] != 0) {
      continue;
    }
    if (!inSomeView(views, rig, mount, seenSamples[i])) {
      ++undecoded;
    } else if (!inSomeView(cleaned, rig, mount, seenSamples[i])) {
      ++removed;
    } else {
      ++unmeshed;
    }
  }
  std::size_t wellSeenCount = 0;
  std::size_t wellSeenCovered = 0;
  for (std::size_t i = 0; i < visible; ++i) {
    if (wellSeen[i] != 0) {
      ++wellSeenCount;
      wellSeenCovered += covered[i] != 0 ? 1U : 0U;
    }
  }
  result.wellSeenShare =
      visible > 0 ? static_cast<double>(wellSeenCount) / static_cast<double>(visible) : 0.0;
  result.wellSeenCoverage =
      wellSeenCount > 0 ? static_cast<double>(wellSeenCovered) / static_cast<double>(wellSeenCount)
                        : 0.0;
  const auto share = [visible](std::size_t n) {
    return visible > 0 ? static_cast<double>(n) / static_cast<double>(visible) : 0.0;
  };
  result.missedUndecoded = share(undecoded);
  result.missedCleaned = share(removed);
  result.missedUnmeshed = share(unmeshed);
  say(text::printfText(
      "  turntable: mesh %.3f mm mean, %.3f mm p95; coverage %.1f %% (never decoded %.1f %%, "
      "cleaned away %.1f %%, not meshed %.1f %%); %.1f %% of it seen within %.0f° of head-on, "
      "covered %.1f %%",
      result.meanMm, result.p95Mm, 100.0 * result.coverage, 100.0 * result.missedUndecoded,
      100.0 * result.missedCleaned, 100.0 * result.missedUnmeshed, 100.0 * result.wellSeenShare,
      kWellSeenDeg, 100.0 * result.wellSeenCoverage));

  // The same views with narrower margins at holes and jumps.
  for (int margin = fuse.clean.edgePx - 1; margin >= 0; --margin) {
    fuse.clean.edgePx = margin;
    result.margins.push_back(fuseAndMeasure(views, rig, fuse, truth, seenSamples).margin);
    say(text::printfText("  margin %d px: mesh %.3f mm mean, %.3f mm p95; coverage %.1f %%", margin,
                         result.margins.back().meanMm, result.margins.back().p95Mm,
                         100.0 * result.margins.back().coverage));
  }
  return result;
}

}  // namespace smx::scan_eval
