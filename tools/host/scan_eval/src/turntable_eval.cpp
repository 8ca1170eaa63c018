#include "smx/scan_eval/turntable_eval.hpp"

#include <open3d/Open3D.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
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

double seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

const sim::TurntableMount& mountOf(const sim::Scene& scene) {
  if (!scene.turntable) {
    throw std::runtime_error("the scene has no turntable");
  }
  return *scene.turntable;
}

// The scene with its table turned by `deg`: objects on it are turned about the table's line.
sim::Scene turned(const sim::Scene& scene, double deg) {
  const auto& mount = mountOf(scene);
  const Eigen::Matrix3d q(Eigen::AngleAxisd(deg * kRadPerDeg, mount.axis.normalized()));
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

// Marks the samples (model frame) that camera `camera` sees lit in `frame`, rendered with the
// table at `deg`.
void markVisible(const eval::SimFrame& frame, int camera, const sim::Scene& scene, double deg,
                 const std::vector<Vec3>& samples, std::vector<char>& seen) {
  const auto& mount = mountOf(scene);
  const Eigen::Matrix3d q(Eigen::AngleAxisd(deg * kRadPerDeg, mount.axis.normalized()));
  const auto& device = frame.rig.cameras.at(static_cast<std::size_t>(camera));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (seen[i] != 0) {
      continue;
    }
    const Vec3 w = q * (samples[i] - mount.pivot) + mount.pivot;
    const lens::Point3 world{w.x(), w.y(), w.z()};
    const auto uv = lens::project(device, world);
    if (!uv) {
      continue;
    }
    const int x = static_cast<int>(std::lround(uv->x));
    const int y = static_cast<int>(std::lround(uv->y));
    if (x < 0 || y < 0 || x >= device.width || y >= device.height) {
      continue;
    }
    const double z = lens::toDevice(device, world)[2];
    const double truth = frame.depth.at(x, y);
    bool lit = false;
    for (const auto& mask : frame.lit) {
      lit = lit || mask.at(x, y) != 0;
    }
    if (lit && std::isfinite(truth) && std::abs(z - truth) < kVisibleM) {
      seen[i] = 1;
    }
  }
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
  const auto sampled = scanned.SamplePointsUniformly(kSurfaceSamples);
  const std::vector<Vec3>& samples = sampled->points_;
  std::vector<char> seen(samples.size(), 0);

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
      markVisible(frame, c, scene, deg, samples, seen);
    }
    views.push_back(std::move(view));
    say(text::printfText("  view %d/%d at %.1f° rendered and decoded", k + 1, options.views, deg));
  }
  result.decodeS = seconds(decodeStart);

  scan::FuseOptions fuse;
  fuse.voxelM = options.voxelM;
  fuse.axis = scan::TurntableAxis{.direction = mount.axis.normalized(), .point = mount.pivot};
  fuse.tableRadiusM = options.tableRadiusM;
  const auto fuseStart = Clock::now();
  auto fused = scan::fuseViews(views, rig, {}, fuse);
  result.fuseS = seconds(fuseStart);
  if (!fused) {
    throw std::runtime_error("fusing the views: " + fused.error().message);
  }
  result.fusedViews = static_cast<int>(fused->report.fusedViews);
  result.loopClosureMm = fused->report.loopClosureM * 1000.0;
  const auto& vertices = fused->mesh.vertices;
  result.meshVertices = vertices.size();
  if (vertices.empty()) {
    throw std::runtime_error("the fused mesh is empty");
  }

  // Vertices to the true surface.
  const auto distance = detail::distancesToSurface(vertices, truth);
  result.meanMm = distance.meanMm;
  result.p95Mm = distance.p95Mm;

  // The seen surface within reach of the mesh's triangles.
  open3d::geometry::TriangleMesh fusedMesh;
  fusedMesh.vertices_ = vertices;
  fusedMesh.triangles_ = fused->mesh.triangles;
  std::vector<Vec3> seenSamples;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (seen[i] != 0) {
      seenSamples.push_back(samples[i]);
    }
  }
  const std::size_t visible = seenSamples.size();
  const std::size_t covered = detail::countWithin(seenSamples, fusedMesh, kCoveredM);
  result.coverage = visible > 0 ? static_cast<double>(covered) / static_cast<double>(visible) : 0;
  return result;
}

}  // namespace smx::scan_eval
