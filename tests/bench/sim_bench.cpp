// Render speed of the simulated camera (hal/sim). Run:
//   build/host/tests/bench/sim_bench
// The target: a 640×480 frame, 3 projectors, 2×2 supersampling, a 70k-triangle mesh
// (the Stanford bunny, 69,451 triangles) under 1 s on a 2-core machine.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "smx/config/rig_json.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/sim/renderer.hpp"
#include "source_dir.hpp"

namespace {

struct Setup {
  smx::algo::Rig rig;
  std::unique_ptr<smx::sim::Renderer> renderer;
};

Setup load(const std::string& rigName, const std::string& sceneName, int supersampling) {
  const std::string root = smx::test::sourceDir().string();
  auto rig = smx::config::loadRig(root + "/boards/sim/" + rigName + ".json");
  auto scene = smx::config::loadScene(root + "/hal/sim/scenes/" + sceneName + ".json");
  if (!rig || !scene) {
    std::fprintf(stderr, "cannot load %s / %s\n", rigName.c_str(), sceneName.c_str());
    std::abort();
  }
  scene->supersampling = supersampling;
  auto renderer = smx::sim::Renderer::create(*rig, *scene);
  if (!renderer) {
    std::fprintf(stderr, "%s\n", renderer.error().c_str());
    std::abort();
  }
  return {*rig, std::move(*renderer)};
}

// args: supersampling, with ground truth (0/1)
void renderFrame(benchmark::State& state, const std::string& rigName,
                 const std::string& sceneName) {
  auto setup = load(rigName, sceneName, static_cast<int>(state.range(0)));
  const auto& cam = setup.rig.cameras.front();
  const std::size_t n = static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height);
  std::vector<smx::algo::Rgb8> pixels(n);
  auto image = *smx::algo::RgbView::packed(pixels, cam.width, cam.height);
  std::vector<float> depth(n);
  smx::sim::GroundTruthViews truth;
  truth.depth = *smx::algo::ImageView<float>::packed(depth, cam.width, cam.height);
  smx::sim::FrameRequest request;
  request.lit.assign(setup.rig.projectors.size(), true);
  request.seed = 1;
  for (auto _ : state) {
    auto r = setup.renderer->render(request, image, state.range(1) != 0 ? &truth : nullptr);
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(pixels.data());
    ++request.frame;
  }
  state.counters["px/s"] =
      benchmark::Counter(static_cast<double>(n) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
  state.counters["projectors"] = static_cast<double>(setup.rig.projectors.size());
}

BENCHMARK_CAPTURE(renderFrame, bunny_3proj, "rig_3proj_1cam", "bunny")
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"ss", "truth"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(renderFrame, plane_2proj, "rig_2proj_1cam", "plane")
    ->ArgsProduct({{2}, {0}})
    ->ArgNames({"ss", "truth"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
