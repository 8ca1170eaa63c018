#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "smx/config/rig_json.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/scan/range_view.hpp"
#include "smx/sim/renderer.hpp"
#include "source_dir.hpp"

// Range views of the scan tests: the simulator's exact depth (its ray-cast ground truth, no
// decoding) of one object, turned on a virtual turntable about a known axis. Independent of the
// scan library: the truth is the scene itself.
namespace smx::scan::test {

inline constexpr double kDepthUnitM = 1e-4;

// The two-camera simulated rig (cameras with lens distortion).
inline algo::Rig twoCameraRig() {
  return *config::loadRig(smx::test::sourceDir() / "boards" / "sim" / "rig_3proj_2cam.json");
}

// The turntable of the "turntable" scene: about −y through (0, 0, 0.9).
inline TurntableAxis tableAxis() {
  return {.direction = -Eigen::Vector3d::UnitY(), .point = Eigen::Vector3d(0, 0, 0.9)};
}

// The table turned by `deg`: a point on it moves to motion · X.
inline Eigen::Isometry3d tableMotion(const TurntableAxis& axis, double deg) {
  return Eigen::Translation3d(axis.point) *
         Eigen::AngleAxisd(deg * std::numbers::pi / 180.0, axis.direction) *
         Eigen::Translation3d(-axis.point);
}

inline sim::Scene sphereScene(double radiusM, const Eigen::Vector3d& centre) {
  sim::Scene scene;
  scene.supersampling = 1;
  sim::Object ball;
  ball.name = "ball";
  ball.shape = sim::Sphere{radiusM};
  ball.pose.t = centre;
  scene.objects.push_back(ball);
  return scene;
}

// The bunny of the named scenes without the wall behind it.
inline sim::Scene bunnyScene() {
  auto scene = config::loadScene(smx::test::sourceDir() / "hal" / "sim" / "scenes" / "bunny.json");
  sim::Scene out = *scene;
  out.supersampling = 1;
  out.objects.resize(1);
  return out;
}

// The view with the table (and every object on it) turned by `deg`.
inline RangeView renderView(const algo::Rig& rig, sim::Scene scene, const TurntableAxis& axis,
                            double deg, const std::string& id) {
  const Eigen::Isometry3d motion = tableMotion(axis, deg);
  for (auto& object : scene.objects) {
    object.pose.R = motion.linear() * object.pose.R;
    object.pose.t = motion * object.pose.t;
  }
  auto renderer = sim::Renderer::create(rig, scene);
  RangeView view;
  view.id = id;
  view.depthUnitM = kDepthUnitM;
  view.turntableDeg = deg;
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    const auto& camera = rig.cameras[c];
    const auto pixels =
        static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
    std::vector<algo::Rgb8> image(pixels);
    std::vector<float> depth(pixels);
    sim::GroundTruthViews truth;
    truth.depth = *algo::ImageView<float>::packed(depth, camera.width, camera.height);
    sim::FrameRequest request;
    request.camera = static_cast<int>(c);
    request.lit.assign(rig.projectors.size(), false);
    if (!renderer ||
        !(*renderer)->render(request, *algo::RgbView::packed(image, camera.width, camera.height),
                             &truth)) {
      return view;  // no cameras: the caller's checks fail
    }
    CameraRange range;
    range.width = camera.width;
    range.height = camera.height;
    range.depth.resize(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
      const double z = depth[i];
      range.depth[i] = std::isfinite(z) && z > 0
                           ? static_cast<std::uint16_t>(std::lround(z / kDepthUnitM))
                           : std::uint16_t{0};
    }
    view.cameras.push_back(std::move(range));
  }
  return view;
}

}  // namespace smx::scan::test
