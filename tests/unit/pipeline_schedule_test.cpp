// Algorithm beside schedule, for the stages after demultiplexing: decoding, triangulation with
// its filters, and merging each have a plain scalar definition (useReferenceKernels) and the
// schedule run() takes. Given the same frame both must give every plane bit for bit: the stripe
// coordinates, boundary levels, each projector's depth and confidence, the merged depth and its
// confidence, and the decoder's counts. The frames are superposed synthetic patterns at the
// example rigs' predicted directions, with a shadowed disc and noise (every target), and in the
// host's optimised build the simulator's renders of named scenes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "smx/algo/arena.hpp"
#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/depth_edges.hpp"
#include "smx/algo/range_merge.hpp"
#include "smx/config/rig_json.hpp"
#include "source_dir.hpp"
#include "synthetic_stripes.hpp"

#if SMX_REFERENCE_SIM_SCENES
#include "smx/eval/sim_frame.hpp"
#endif

namespace smx::algo {
namespace {

struct Frame {
  std::string name;
  Rig rig;
  int width = 0;
  int height = 0;
  std::vector<Rgb8> image;
};

// The median over tiles of a projector's predicted direction, in degrees.
double predictedDegrees(const CameraPipelineSetup& setup, int projector) {
  const auto n = static_cast<std::size_t>(setup.layout.projectors);
  std::vector<std::uint16_t> raw;
  for (std::size_t i = static_cast<std::size_t>(projector); i < setup.predictedAngles.size();
       i += n) {
    raw.push_back(setup.predictedAngles[i]);
  }
  std::nth_element(raw.begin(), raw.begin() + static_cast<std::ptrdiff_t>(raw.size() / 2),
                   raw.end());
  return raw[raw.size() / 2] * 360.0 / 65536.0;
}

// The rig's patterns as straight stripes of 5 px at its predicted directions, a disc in its
// middle in shadow (silhouettes and holes for the filters), a varying surface colour and noise.
Frame syntheticFrame(const std::string& rigFile, unsigned seed) {
  auto rig = config::loadRig(test::sourceDir() / "boards" / "sim" / rigFile);
  EXPECT_TRUE(rig.has_value());
  Frame f{rigFile, *rig, rig->cameras[0].width, rig->cameras[0].height, {}};
  const auto setup = prepareCameraPipeline(f.rig, 0);
  EXPECT_TRUE(setup.has_value());
  std::vector<test::SyntheticPattern> patterns;
  for (int p = 0; p < setup->layout.projectors; ++p) {
    patterns.push_back({predictedDegrees(*setup, p), 5.0});
  }
  f.image = test::superpose(patterns, f.width, f.height);
  const int cx = f.width / 3;
  const int cy = f.height / 2;
  const int r = f.height / 5;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      if ((x - cx) * (x - cx) + (y - cy) * (y - cy) < r * r) {
        f.image[static_cast<std::size_t>(y * f.width + x)] = {12, 12, 12};
      }
    }
  }
  test::colourAndNoise(f.image, f.width, f.height, seed);
  return f;
}

#if SMX_REFERENCE_SIM_SCENES
Frame renderedFrame(const std::string& rigFile, const std::string& scene) {
  eval::SimRequest request;
  request.rigFile = rigFile;
  request.scene = scene;
  const eval::SimFrame sim = eval::renderSimFrame(request);
  return {scene + " " + rigFile, sim.rig, sim.image.width, sim.image.height, sim.image.pixels};
}
#endif

const std::vector<Frame>& frames() {
  static const std::vector<Frame> kFrames = [] {
    std::vector<Frame> f;
    f.push_back(syntheticFrame("rig_2proj_1cam.json", 3));
    f.push_back(syntheticFrame("rig_3proj_1cam.json", 4));
#if SMX_REFERENCE_SIM_SCENES
    f.push_back(renderedFrame("rig_2proj_1cam.json", "bunny"));
    f.push_back(renderedFrame("rig_3proj_1cam.json", "statue"));
    f.push_back(renderedFrame("rig_2proj_1cam.json", "cups"));
#endif
    return f;
  }();
  return kFrames;
}

// One camera's pipeline over its own arena.
struct Pipeline {
  std::vector<std::byte> memory;
  Arena arena;
  CameraPipeline pipeline;

  static Pipeline make(const CameraPipelineSetup& setup) {
    return Pipeline(setup, *CameraPipeline::workspaceBytes(setup));
  }

 private:
  Pipeline(const CameraPipelineSetup& setup, std::size_t bytes)
      : memory(bytes), arena(memory), pipeline(*CameraPipeline::create(setup, arena)) {}
};

// The first differing pixel of two planes, or "" when they are equal.
template <class T>
std::string firstDifference(ImageView<const T> a, ImageView<const T> b) {
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      if (a.rowPtr(y)[x] != b.rowPtr(y)[x]) {
        char text[96];
        std::snprintf(text, sizeof text, "(%d, %d): schedule %lld, reference %lld", x, y,
                      static_cast<long long>(a.rowPtr(y)[x]),
                      static_cast<long long>(b.rowPtr(y)[x]));
        return text;
      }
    }
  }
  return "";
}

// Rows whose bytes differ, for planes of structs.
template <class T>
int rowsDiffering(ImageView<const T> a, ImageView<const T> b) {
  int rows = 0;
  for (int y = 0; y < a.height(); ++y) {
    rows +=
        std::memcmp(a.rowPtr(y), b.rowPtr(y), sizeof(T) * static_cast<std::size_t>(a.width())) != 0
            ? 1
            : 0;
  }
  return rows;
}

TEST(PipelineSchedule, EveryStageAfterDemuxGivesTheReferenceBitForBit) {
  for (const Frame& f : frames()) {
    SCOPED_TRACE(f.name);
    const auto setup = prepareCameraPipeline(f.rig, 0);
    ASSERT_TRUE(setup.has_value()) << setup.error();
    Pipeline schedule = Pipeline::make(*setup);
    Pipeline reference = Pipeline::make(*setup);
    reference.pipeline.useReferenceKernels(true);
    const ConstRgbView image = *ConstRgbView::packed(f.image, f.width, f.height);
    ASSERT_TRUE(schedule.pipeline.run(image));
    ASSERT_TRUE(reference.pipeline.run(image));
    const CameraPipeline& s = schedule.pipeline;
    const CameraPipeline& r = reference.pipeline;
    int depthPixels = 0;
    for (int p = 0; p < s.projectors(); ++p) {
      SCOPED_TRACE("projector " + std::to_string(p));
      EXPECT_EQ(firstDifference(s.stripe(p), r.stripe(p)), "") << "stripe";
      EXPECT_EQ(firstDifference(s.levels(p), r.levels(p)), "") << "levels";
      EXPECT_EQ(firstDifference(s.depth(p), r.depth(p)), "") << "depth";
      EXPECT_EQ(firstDifference(s.confidence(p), r.confidence(p)), "") << "confidence";
      const DecodeStats& a = s.decodeStats(p);
      const DecodeStats& b = r.decodeStats(p);
      EXPECT_EQ(a.boundaryPixels, b.boundaryPixels);
      EXPECT_EQ(a.votedPixels, b.votedPixels);
      EXPECT_EQ(a.decodedPixels, b.decodedPixels);
      EXPECT_EQ(a.curves, b.curves);
      EXPECT_EQ(a.densePixels, b.densePixels);
      depthPixels += a.densePixels;
    }
    EXPECT_EQ(firstDifference(s.merged(), r.merged()), "") << "merged depth";
    EXPECT_EQ(firstDifference(s.confidence(), r.confidence()), "") << "merged confidence";
    // The frame must exercise the stages: a good share of it decodes.
    EXPECT_GT(depthPixels, f.width * f.height / 10);
  }
}

// Runs each job on a thread of its own, all at once, started in reverse order: whatever two
// lanes or bands share shows as a difference from the serial run.
class ThreadPerJob final : public JobRunner {
 public:
  explicit ThreadPerJob(int width) : width_(width) {}
  void runJobs(int count, void* context, Call call) override {
    std::vector<std::thread> threads;
    for (int i = count - 1; i >= 0; --i) {
      threads.emplace_back([=] { call(context, i); });
    }
    for (std::thread& t : threads) {
      t.join();
    }
  }
  [[nodiscard]] int width() const override { return width_; }

 private:
  int width_;
};

TEST(PipelineSchedule, LanesAndBandsGiveTheSerialPlanesBitForBit) {
  for (const Frame& f : frames()) {
    SCOPED_TRACE(f.name);
    const auto serialSetup = prepareCameraPipeline(f.rig, 0);
    ASSERT_TRUE(serialSetup.has_value()) << serialSetup.error();
    Pipeline serial = Pipeline::make(*serialSetup);
    const ConstRgbView image = *ConstRgbView::packed(f.image, f.width, f.height);
    ASSERT_TRUE(serial.pipeline.run(image));
    for (const int lanes : {2, 3}) {
      PipelineOptions options;
      options.lanes = lanes;
      const auto setup = prepareCameraPipeline(f.rig, 0, options);
      ASSERT_TRUE(setup.has_value()) << setup.error();
      Pipeline parallel = Pipeline::make(*setup);
      // More lanes than projectors would idle: the setup asks for no more.
      ASSERT_EQ(parallel.pipeline.lanes(),
                std::min(lanes, static_cast<int>(f.rig.projectors.size())));
      // Two frames, so that a lane's state left from the first would show in the second.
      for (const int bands : {lanes, 7}) {
        SCOPED_TRACE(std::to_string(lanes) + " lanes, " + std::to_string(bands) + " bands");
        ThreadPerJob jobs(bands);
        ASSERT_TRUE(parallel.pipeline.run(image, jobs));
        const CameraPipeline& a = parallel.pipeline;
        const CameraPipeline& b = serial.pipeline;
        for (int p = 0; p < a.projectors(); ++p) {
          SCOPED_TRACE("projector " + std::to_string(p));
          EXPECT_EQ(rowsDiffering(a.demux().boundaries(p), b.demux().boundaries(p)), 0)
              << "boundaries";
          EXPECT_EQ(firstDifference(a.stripe(p), b.stripe(p)), "") << "stripe";
          EXPECT_EQ(firstDifference(a.levels(p), b.levels(p)), "") << "levels";
          EXPECT_EQ(firstDifference(a.depth(p), b.depth(p)), "") << "depth";
          EXPECT_EQ(firstDifference(a.confidence(p), b.confidence(p)), "") << "confidence";
          EXPECT_EQ(a.decodeStats(p).densePixels, b.decodeStats(p).densePixels);
          EXPECT_EQ(a.decodeStats(p).curves, b.decodeStats(p).curves);
        }
        EXPECT_EQ(firstDifference(a.merged(), b.merged()), "") << "merged depth";
        EXPECT_EQ(firstDifference(a.confidence(), b.confidence()), "") << "merged confidence";
      }
    }
  }
}

TEST(PipelineSchedule, LanesBeyondTheProjectorsAreRefused) {
  const Frame& f = frames().front();
  auto setup = prepareCameraPipeline(f.rig, 0);
  ASSERT_TRUE(setup.has_value());
  setup->lanes = setup->layout.projectors + 1;
  EXPECT_FALSE(CameraPipeline::workspaceBytes(*setup).has_value());
  setup->lanes = 0;
  EXPECT_FALSE(CameraPipeline::workspaceBytes(*setup).has_value());
}

// Range images that take the merge's every branch: one smooth surface measured by up to eight
// ranges with noise, holes, outliers and values on a quantised grid (equal variances: unions),
// and the filter's jumps; the image sizes leave no border unvisited. Dense ranges on a wide
// image give full windows (taken whole, in unions too) across the schedule's chunks of columns.
// Noise as wide as the tolerance, at and past the span within which the schedule's 32-bit window
// spreads are exact, gives spreads past 2^32 where it must not compare them.
TEST(PipelineSchedule, MergeAndEdgeFilterGiveTheReferenceOnRandomRanges) {
  std::mt19937 rng(7);
  struct Holes {
    int width;
    int missingPct;
    int outlierPct;
    bool blankBands;  // each range without values in bands of columns, the bands shifted per range
  };
  struct Values {
    int base;
    int noise;  // ± this, uniform
    DepthTolerance tolerance;
  };
  for (const Values values : {Values{9000, 20, {50, 10}}, Values{30000, 7300, {7327, 0}},
                              Values{30000, 10000, {7328, 0}}, Values{30000, 10000, {10000, 0}}}) {
    for (const Holes holes :
         {Holes{37, 20, 10, false}, Holes{150, 2, 2, false}, Holes{150, 2, 2, true}}) {
      for (const int ranges : {1, 2, 3, 5, 8}) {
        for (const int quantum : {1, 8, 64}) {
          SCOPED_TRACE("noise ±" + std::to_string(values.noise) + ", tolerance " +
                       std::to_string(values.tolerance.minUnits) + ", " + std::to_string(ranges) +
                       " ranges, quantum " + std::to_string(quantum) + ", width " +
                       std::to_string(holes.width) + (holes.blankBands ? ", blank bands" : ""));
          const int w = holes.width;
          const int h = 23;
          const auto pixels = static_cast<std::size_t>(w * h);
          std::vector<std::vector<std::uint16_t>> depth(static_cast<std::size_t>(ranges));
          std::vector<std::vector<std::uint8_t>> confidence(static_cast<std::size_t>(ranges));
          std::vector<ConstDepthPlane> views;
          std::vector<ImageView<const std::uint8_t>> confidenceViews;
          std::uniform_int_distribution<int> noise(-values.noise, values.noise);
          std::uniform_int_distribution<int> outlier(-800, 800);
          std::uniform_int_distribution<int> percent(0, 99);
          for (std::size_t r = 0; r < depth.size(); ++r) {
            depth[r].resize(pixels);
            confidence[r].resize(pixels);
            for (std::size_t i = 0; i < pixels; ++i) {
              const int x = static_cast<int>(i) % w;
              const int roll = percent(rng);
              int z = values.base + 15 * x + noise(rng);
              z = z / quantum * quantum;
              if (roll < holes.missingPct ||
                  (holes.blankBands && (x / 6 + static_cast<int>(r)) % 3 == 0)) {
                z = kNoDepth;
              } else if (roll < holes.missingPct + holes.outlierPct) {
                z = values.base / 2 + outlier(rng);  // an outlier or another surface
              }
              depth[r][i] = static_cast<std::uint16_t>(z);
              confidence[r][i] =
                  static_cast<std::uint8_t>(z == kNoDepth ? 0 : 1 + percent(rng) * 2);
            }
            views.push_back(*ConstDepthPlane::packed(depth[r], w, h));
            confidenceViews.push_back(*ImageView<const std::uint8_t>::packed(confidence[r], w, h));
          }
          std::vector<std::uint16_t> merged(pixels);
          std::vector<std::uint16_t> mergedReference(pixels);
          std::vector<std::uint8_t> mergedConfidence(pixels);
          std::vector<std::uint8_t> mergedConfidenceReference(pixels);
          const DepthTolerance tolerance = values.tolerance;
          ASSERT_TRUE(mergeRanges(views, confidenceViews, *DepthPlane::packed(merged, w, h),
                                  *ImageView<std::uint8_t>::packed(mergedConfidence, w, h),
                                  tolerance));
          ASSERT_TRUE(mergeRangesReference(
              views, confidenceViews, *DepthPlane::packed(mergedReference, w, h),
              *ImageView<std::uint8_t>::packed(mergedConfidenceReference, w, h), tolerance));
          EXPECT_EQ(merged, mergedReference);
          EXPECT_EQ(mergedConfidence, mergedConfidenceReference);
          EXPECT_GT(std::count_if(merged.begin(), merged.end(),
                                  [](std::uint16_t z) { return z != kNoDepth; }),
                    static_cast<std::ptrdiff_t>(pixels / 4));

          for (const int permille : {0, 5, 20, 1000}) {
            std::vector<std::uint16_t> kept(pixels);
            std::vector<std::uint16_t> keptReference(pixels);
            ASSERT_TRUE(removeDepthEdges(views[0], *DepthPlane::packed(kept, w, h), permille));
            ASSERT_TRUE(removeDepthEdgesReference(
                views[0], *DepthPlane::packed(keptReference, w, h), permille));
            EXPECT_EQ(kept, keptReference) << permille << " per mille";
          }
        }
      }
    }
  }
}

// The schedule orders full windows by 9·Σz² − (Σz)² in 32-bit arithmetic, exact while a window's
// values span at most 14654 (20·14654² < 2^32). Two full windows at one pixel: the first range's
// narrow, the second's four values at the tolerance's low end and five at its high end, so its
// spread is the largest nine values in that span can have. Past the limit that spread wraps to
// less than the narrow window's, and a schedule that compared it would take the wide window.
TEST(PipelineSchedule, MergeNeverComparesWrappedSpreads) {
  constexpr std::uint16_t kRef = 30000;
  for (const int tolerance : {7327, 7328, 9000}) {
    SCOPED_TRACE("tolerance " + std::to_string(tolerance));
    constexpr int kSide = 3;  // one inner pixel
    std::vector<std::uint16_t> narrow(kSide * kSide);
    std::vector<std::uint16_t> wide(kSide * kSide);
    for (std::size_t i = 0; i < narrow.size(); ++i) {
      narrow[i] = i == 4 ? kRef : static_cast<std::uint16_t>(i % 2 == 0 ? kRef - 200 : kRef + 200);
      wide[i] = static_cast<std::uint16_t>(i < 4 ? kRef - tolerance : kRef + tolerance);
    }
    const std::vector<ConstDepthPlane> ranges{*ConstDepthPlane::packed(narrow, kSide, kSide),
                                              *ConstDepthPlane::packed(wide, kSide, kSide)};
    std::vector<std::uint8_t> full(narrow.size(), 200);
    const std::vector<ImageView<const std::uint8_t>> confidences{
        *ImageView<const std::uint8_t>::packed(full, kSide, kSide),
        *ImageView<const std::uint8_t>::packed(full, kSide, kSide)};
    std::vector<std::uint16_t> merged(narrow.size());
    std::vector<std::uint16_t> mergedReference(narrow.size());
    std::vector<std::uint8_t> confidence(narrow.size());
    std::vector<std::uint8_t> confidenceReference(narrow.size());
    const DepthTolerance within{tolerance, 0};
    ASSERT_TRUE(mergeRanges(ranges, confidences, *DepthPlane::packed(merged, kSide, kSide),
                            *ImageView<std::uint8_t>::packed(confidence, kSide, kSide), within));
    ASSERT_TRUE(mergeRangesReference(
        ranges, confidences, *DepthPlane::packed(mergedReference, kSide, kSide),
        *ImageView<std::uint8_t>::packed(confidenceReference, kSide, kSide), within));
    EXPECT_EQ(mergedReference[4], kRef) << "the narrow window has the smaller variance";
    EXPECT_EQ(merged, mergedReference);
    EXPECT_EQ(confidence, confidenceReference);
  }
}

}  // namespace
}  // namespace smx::algo
