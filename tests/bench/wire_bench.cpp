// Range frames on the wire (docs/protocol.md "Bandwidth"): for each named scene, the merged
// range image of camera 0 as the pipeline computes it, RVL-compressed as stripemuxd sends it.
// Counters: bytes per frame, compression ratio against raw 16-bit depth, the link rate one
// camera needs at 30 fps, and the encoder's speed.
#include <benchmark/benchmark.h>

#include <map>
#include <string>
#include <vector>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/eval/sim_frame.hpp"
#include "smx/protocol/messages.hpp"

namespace {

using namespace smx;

struct SceneDepth {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> depth;
};

// Rendered and decoded once per scene.
const SceneDepth& sceneDepth(const std::string& scene, const std::string& rigFile) {
  static std::map<std::string, SceneDepth> cache;
  auto [it, added] = cache.try_emplace(scene);
  if (!added) {
    return it->second;
  }
  const eval::SimFrame frame = eval::renderSimFrame({.rigFile = rigFile, .scene = scene});
  const auto setup = algo::prepareCameraPipeline(frame.rig, 0).value();
  std::vector<std::byte> memory(algo::CameraPipeline::workspaceBytes(setup).value());
  algo::Arena arena(memory);
  auto pipeline = algo::CameraPipeline::create(setup, arena).value();
  if (!pipeline.run(frame.image.view())) {
    throw std::runtime_error("pipeline failed on " + scene);
  }
  const auto merged = pipeline.merged();
  SceneDepth& out = it->second;
  out.width = merged.width();
  out.height = merged.height();
  for (int y = 0; y < merged.height(); ++y) {
    out.depth.insert(out.depth.end(), merged.row(y).begin(), merged.row(y).end());
  }
  return out;
}

void BM_RangeFrameRvl(benchmark::State& state, const std::string& scene,
                      const std::string& rigFile) {
  const SceneDepth& scan = sceneDepth(scene, rigFile);
  const auto plane = *algo::ConstDepthPlane::packed(scan.depth, scan.width, scan.height);
  std::vector<std::byte> buffer(protocol::rangeFrameBound(scan.width, scan.height));
  std::size_t bytes = 0;
  for (auto _ : state) {
    const auto message =
        protocol::encodeRangeFrame({.compression = protocol::Compression::kRvl}, plane, buffer);
    bytes = message->size();
    benchmark::DoNotOptimize(buffer.data());
  }
  const double raw = 2.0 * static_cast<double>(scan.depth.size());
  std::size_t valid = 0;
  for (const auto z : scan.depth) {
    valid += z != 0 ? 1U : 0U;
  }
  state.counters["bytes_per_frame"] = static_cast<double>(bytes);
  state.counters["ratio"] = raw / static_cast<double>(bytes);
  state.counters["Mbit_s_at_30fps"] = static_cast<double>(bytes) * 8 * 30 / 1e6;
  state.counters["valid_px"] = static_cast<double>(valid);
  state.counters["px/s"] = benchmark::Counter(static_cast<double>(scan.depth.size()),
                                              benchmark::Counter::kIsIterationInvariantRate);
}

BENCHMARK_CAPTURE(BM_RangeFrameRvl, plane, std::string("plane"), "rig_2proj_1cam.json");
BENCHMARK_CAPTURE(BM_RangeFrameRvl, sphere, std::string("sphere"), "rig_2proj_1cam.json");
BENCHMARK_CAPTURE(BM_RangeFrameRvl, bunny, std::string("bunny"), "rig_2proj_1cam.json");
BENCHMARK_CAPTURE(BM_RangeFrameRvl, cups, std::string("cups"), "rig_2proj_1cam.json");
BENCHMARK_CAPTURE(BM_RangeFrameRvl, rgbcmy_panel, std::string("rgbcmy_panel"),
                  "rig_2proj_1cam.json");
BENCHMARK_CAPTURE(BM_RangeFrameRvl, statue, std::string("statue"), "rig_3proj_1cam.json");

}  // namespace

BENCHMARK_MAIN();
