#include "smx/eval/sim_frame.hpp"

#include <stdexcept>
#include <utility>

#include "smx/config/rig_json.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/sim/named_scenes.hpp"
#include "smx/sim/renderer.hpp"

namespace smx::eval {

namespace {
template <typename T>
T orThrow(std::expected<T, std::string> value) {
  if (!value) {
    throw std::runtime_error(value.error());
  }
  return *std::move(value);
}
}  // namespace

algo::Rig loadExampleRig(const std::string& file) {
  auto rig = config::loadRig(orThrow(sim::dataDir()) / "boards/sim" / file);
  if (!rig) {
    throw std::runtime_error(rig.error().message());
  }
  return *rig;
}

sim::Scene loadNamedScene(const std::string& name) {
  auto scene = config::loadScene(orThrow(sim::sceneDir()) / (name + ".json"));
  if (!scene) {
    throw std::runtime_error(scene.error().message());
  }
  return *scene;
}

SimFrame renderSimFrame(const SimRequest& request) {
  return renderSimFrame(request, loadNamedScene(request.scene));
}

SimFrame renderSimFrame(const SimRequest& request, const sim::Scene& scene) {
  return renderSimFrame(loadExampleRig(request.rigFile), scene, request);
}

SimFrame renderSimFrame(algo::Rig rig, const sim::Scene& scene, const SimRequest& request) {
  SimFrame f;
  f.rig = std::move(rig);
  const auto& cam = f.rig.cameras.at(static_cast<std::size_t>(request.camera));
  const int w = cam.width;
  const int h = cam.height;
  const std::size_t projectors = f.rig.projectors.size();
  f.image = OwnedPlane<algo::Rgb8>(w, h, algo::Rgb8{0, 0, 0});
  f.depth = OwnedPlane<float>(w, h, 0.0F);
  sim::GroundTruthViews truth;
  truth.depth = f.depth.view();
  for (std::size_t p = 0; p < projectors; ++p) {
    f.lit.emplace_back(w, h, std::uint8_t{0});
    f.stripe.emplace_back(w, h, 0.0F);
  }
  for (std::size_t p = 0; p < projectors; ++p) {
    truth.projectors.push_back({f.lit[p].view(), {}, {}, f.stripe[p].view()});
  }
  sim::Scene sampled = scene;
  if (request.supersampling > 0) {
    sampled.supersampling = request.supersampling;
  }
  auto renderer = sim::Renderer::create(f.rig, sampled);
  if (!renderer) {
    throw std::runtime_error(renderer.error());
  }
  sim::FrameRequest frame;
  frame.camera = request.camera;
  frame.frame = request.frame;
  frame.lit.assign(projectors, true);
  frame.seed = request.seed;
  if (auto ok = (*renderer)->render(frame, f.image.view(), &truth); !ok) {
    throw std::runtime_error(ok.error());
  }
  return f;
}

}  // namespace smx::eval
