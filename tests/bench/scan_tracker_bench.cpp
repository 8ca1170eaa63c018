// scan::Tracker per frame on the head_handheld scene's true depth (640×480, 2 projectors, 1
// camera): the whole track() and its stages, frames per second as the counter
// (docs/tracking.md, speed). Run with the optimised host preset.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "frame_cloud.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/scan/tracker.hpp"
#include "smx/sim/renderer.hpp"
#include "source_dir.hpp"
#include "voxel_cloud.hpp"

namespace {

using namespace smx;

constexpr int kFrames = 24;

struct Frames {
  algo::Rig rig;
  std::vector<scan::RangeView> views;
};

const Frames& frames() {
  static const Frames f = [] {
    Frames out;
    auto rig = config::loadRig(smx::test::sourceDir() / "boards/sim-handheld/rig.json");
    auto scene = config::loadScene(smx::test::sourceDir() / "hal/sim/scenes/head_handheld.json");
    if (!rig || !scene) {
      std::fprintf(stderr, "cannot load the rig or the scene\n");
      std::abort();
    }
    scene->supersampling = 1;
    scene->camera.exposure = 0;
    scene->camera.noiseSigma = sim::Vec3::Zero();
    out.rig = *rig;
    auto renderer = sim::Renderer::create(out.rig, *scene);
    const auto& camera = out.rig.cameras[0];
    const auto count = static_cast<std::size_t>(camera.width * camera.height);
    std::vector<algo::Rgb8> image(count);
    std::vector<float> depth(count);
    sim::GroundTruthViews truth;
    truth.depth = *algo::ImageView<float>::packed(depth, camera.width, camera.height);
    for (int i = 0; i < kFrames; ++i) {
      sim::FrameRequest request;
      request.frame = i;
      request.lit.assign(out.rig.projectors.size(), false);
      if (!(*renderer)->render(request, *algo::RgbView::packed(image, camera.width, camera.height),
                               &truth)) {
        std::abort();
      }
      scan::RangeView view;
      scan::CameraRange range{
          camera.width, camera.height, std::vector<std::uint16_t>(count, 0), {}};
      for (std::size_t p = 0; p < count; ++p) {
        if (std::isfinite(depth[p])) {
          range.depth[p] = static_cast<std::uint16_t>(std::lround(depth[p] / view.depthUnitM));
        }
      }
      view.cameras.push_back(std::move(range));
      out.views.push_back(std::move(view));
    }
    return out;
  }();
  return f;
}

// A fresh tracker over the sequence: the mean time per frame (the first starts the model).
void BM_TrackFrame(benchmark::State& state) {
  const Frames& f = frames();
  std::int64_t n = 0;
  for (auto _ : state) {
    auto tracker = scan::Tracker::create(f.rig);
    for (const auto& v : f.views) {
      benchmark::DoNotOptimize(tracker->track(v));
    }
    n += kFrames;
  }
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TrackFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

// The frame's oriented points (ray table, grid normals) and their voxel grid.
void BM_FrameCloud(benchmark::State& state) {
  const Frames& f = frames();
  const scan::detail::FrameCloud cloud(f.rig, {});
  for (auto _ : state) {
    const scan::Cloud points = cloud.points(f.views[5]);
    scan::detail::VoxelCloud grid(0.002);
    grid.add(points);
    benchmark::DoNotOptimize(grid.cloud());
  }
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FrameCloud)->Unit(benchmark::kMillisecond)->UseRealTime();

// Frame-to-model ICP alone: frame 6 onto frame 5's cloud (as a model of one frame).
void BM_Icp(benchmark::State& state) {
  const Frames& f = frames();
  const scan::detail::FrameCloud cloud(f.rig, {});
  scan::detail::VoxelCloud a(0.002);
  a.add(cloud.points(f.views[5]));
  scan::detail::VoxelCloud b(0.002);
  b.add(cloud.points(f.views[6]));
  const scan::Cloud target = a.cloud();
  const scan::Cloud source = b.cloud();
  scan::IcpOptions icp = scan::TrackerOptions{}.icp;
  if (state.range(0) > 0) {  // levels (mm) and iterations other than the tracker's
    icp.levelVoxelsM = {0.001 * static_cast<double>(state.range(0)),
                        0.001 * static_cast<double>(state.range(1))};
    icp.iterationsPerLevel = static_cast<int>(state.range(2));
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(scan::registerIcp(source, target, scan::Pose::Identity(), icp));
  }
  state.counters["points"] = static_cast<double>(source.size());
}
BENCHMARK(BM_Icp)
    ->Args({0, 0, 0})
    ->Args({8, 3, 10})
    ->Args({6, 2, 10})
    ->Args({6, 3, 10})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
