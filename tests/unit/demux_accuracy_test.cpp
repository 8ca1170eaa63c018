// Orientation demultiplexing against simulator ground truth (fixed seeds, the paper's noise):
// encoding directions, boundary recall / precision / class / sub-pixel position.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "boundary_eval.hpp"
#include "sim_frame.hpp"
#include "smx/algo/demux.hpp"
#include "smx/algo/encoding_prediction.hpp"

namespace smx::algo {
namespace {

struct DemuxRun {
  std::vector<std::byte> memory;
  std::optional<Arena> arena;
  std::optional<Demultiplexer> demux;
};

std::unique_ptr<DemuxRun> runDemux(const test::SimFrame& f, const DemuxParams& params = {}) {
  auto run = std::make_unique<DemuxRun>();
  DemuxLayout layout{f.image.width, f.image.height, static_cast<int>(f.rig.projectors.size()),
                     params};
  const auto bytes = Demultiplexer::workspaceBytes(layout);
  EXPECT_TRUE(bytes.has_value());
  run->memory.resize(*bytes);
  run->arena.emplace(run->memory);
  const auto predicted = predictEncodingAngles(f.rig, 0, layout, 0.9);
  EXPECT_TRUE(predicted.has_value()) << predicted.error();
  auto d = Demultiplexer::create(layout, *predicted, *run->arena);
  EXPECT_TRUE(d.has_value()) << d.error().message;
  run->demux.emplace(std::move(*d));
  const auto ok = run->demux->run(f.image.view());
  EXPECT_TRUE(ok.has_value());
  return run;
}

void report(const char* name, const test::SimFrame& f, const Demultiplexer& d) {
  std::vector<ImageView<const std::uint8_t>> lits;
  for (const auto& l : f.lit) {
    lits.push_back(l.view());
  }
  for (int n = 1; n <= static_cast<int>(lits.size()); ++n) {
    const auto region =
        test::smoothOnly(test::erode(test::litByExactly(lits, n), 3), f.depth.view(), 0.02);
    for (std::size_t p = 0; p < lits.size(); ++p) {
      test::Mask mine = region;
      for (int y = 0; y < mine.height; ++y) {
        for (int x = 0; x < mine.width; ++x) {
          mine.at(x, y) = (mine.at(x, y) != 0 && lits[p](x, y) != 0) ? 255 : 0;
        }
      }
      if (mine.count() < 100) continue;
      const auto s = test::scoreBoundaries(d.boundaries(static_cast<int>(p)),
                                           d.directions(static_cast<int>(p)), f.stripe[p].view(),
                                           mine.view());
      const auto a = test::scoreDirections(d.directions(static_cast<int>(p)), f.stripe[p].view(),
                                           mine.view());
      std::printf("%s lit-by-%d proj%zu px=%d dir med %.2f p95 %.2f | true %d det %d recall %.4f "
                  "precision %.4f class %.4f rms %.3f bias %.3f\n",
                  name, n, p, mine.count(), a.medianDeg, a.p95Deg, s.trueBoundaries, s.detected,
                  s.recall, s.precision, s.classAccuracy, s.positionRmsPx, s.positionMeanPx);
    }
  }
}

TEST(DemuxAccuracy, Explore) {
  for (const auto& [rigFile, scene] : std::vector<std::pair<std::string, std::string>>{
           {"rig_2proj_1cam.json", "plane"}, {"rig_2proj_1cam.json", "sphere"},
           {"rig_3proj_1cam.json", "plane"}, {"rig_2proj_1cam.json", "rgbcmy_panel"}}) {
    const auto f = test::renderSimFrame({rigFile, scene});
    const auto run = runDemux(f);
    report((rigFile + "/" + scene).c_str(), f, *run->demux);
  }
}

}  // namespace
}  // namespace smx::algo
