// Speed of orientation demultiplexing (docs/demux.md "Speed") and of the whole pipeline
// (docs/decode.md "Speed"), single thread, against one
// OpenCV cv::Sobel (CV_16S, 3×3, x only) over the same RGB frame measured in the same process.
// Run:
//   build/host/tests/bench/demux_bench
//   build/host/tests/bench/demux_bench --benchmark_filter=640x480_2proj
//
// Frames: the simulator renders the plane scene once at start-up for rig_2proj_1cam (with one
// projector, its first, and with both) and rig_3proj_1cam at 640×480, and for the same rigs
// with camera 0 scaled to 1280×960.
// Per configuration:
//   <cfg>/sobel        cv::Sobel(frame, dst, CV_16S, 1, 0, 3) on the frame as CV_8UC3;
//   <cfg>/demux        Demultiplexer::run() (the whole frame; arena from workspaceBytes()),
//                      with the kernels' AVX2 build where the CPU has it (context
//                      demux_kernels), as OpenCV dispatches its Sobel;
//   <cfg>/demux_baseline
//                      the same with DemuxSchedule::kBaseline: the SSE2 build, what an x86-64
//                      without AVX2 runs (checked equal to <cfg>/demux's output first);
//   <cfg>/1_smooth … <cfg>/8_boundaries
//                      each kernel of algo/src/frame/demux_kernels.hpp alone (the build
//                      <cfg>/demux runs), wired as run() wires them, over buffers owned here (one
//                      separated plane set per projector, so stage 8 reads what stage 7 wrote for
//                      that projector); separate and boundaries cover all projectors. Before
//                      timing, the stage chain is run once and its boundaries and directions are
//                      checked equal to run()'s.
//   <cfg>/pipeline     CameraPipeline::run(): demux, decode, triangulate and merge
//   (docs/decode.md); <cfg>/p_decode, p_triangulate, p_merge
//                      those stages alone, on the output of the pipeline's last run.
//   <cfg>/pipeline_2threads, p2_decode, p2_triangulate, p2_merge
//                      the same on two threads (the firmware's worker pool): a lane per
//                      projector for decoding and triangulation, two bands of rows for the merge.
// Counters: px/s (frame pixels per CPU second); x_sobel = this benchmark's CPU time per frame /
// one Sobel's CPU time measured around it (the mean of kLocalSobelCalls calls just before and as
// many just after the benchmark's loop, on the same frame: this shared machine's speed drifts by
// tens of per cent over minutes, so a reference taken once at start-up skews the ratios of the
// benchmarks that run later; the <cfg>/sobel benchmark's own x_sobel checks the figure);
// sobel_ms = that reference; arena = the configuration's Demultiplexer::workspaceBytes(), or
// CameraPipeline::workspaceBytes() for the pipeline benchmarks.
// CPU time is the thread's (CLOCK_THREAD_CPUTIME_ID, the clock of Google Benchmark's CPU
// column): on a shared 2-core machine it is what the code costs, where wall time (the Time
// column, and the steady_clock Sobel figure printed at start-up) also counts other processes.
// Everything runs on one thread: cv::setNumThreads(1), and the demultiplexer has no threads.
#include <benchmark/benchmark.h>

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/core/ocl.hpp>
#include <opencv2/imgproc.hpp>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "demux_kernels.hpp"
#include "smx/algo/arena.hpp"
#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/demux.hpp"
#include "smx/algo/encoding_prediction.hpp"
#include "smx/device/worker_pool.hpp"
#include "smx/eval/sim_frame.hpp"

namespace {

namespace algo = smx::algo;
namespace kern = smx::algo::demux;
using Clock = std::chrono::steady_clock;

constexpr double kNominalDepthM = 0.9;
constexpr int kSobelWarmUp = 20;
constexpr int kSobelCalls = 200;
constexpr int kLocalSobelCalls = 100;

// CPU time of the calling thread, the clock of Google Benchmark's CPU column.
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "demux_bench: %s\n", what.c_str());
  std::exit(1);
}

template <class T>
algo::ImageView<T> viewOf(std::span<T> pixels, int w, int h) {
  auto view = algo::ImageView<T>::packed(pixels, w, h);
  if (!view) {
    die("cannot view a " + std::to_string(w) + "x" + std::to_string(h) + " buffer");
  }
  return *view;
}

std::size_t pixelsOf(int w, int h) {
  return static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
}

// Three planes over one buffer (movable: the views follow the buffer; not copyable).
struct OwnedPlanes3 {
  std::vector<std::int16_t> pixels;
  kern::Planes3 views;

  OwnedPlanes3(const OwnedPlanes3&) = delete;
  OwnedPlanes3& operator=(const OwnedPlanes3&) = delete;
  OwnedPlanes3(OwnedPlanes3&&) = default;
  OwnedPlanes3& operator=(OwnedPlanes3&&) = default;
  ~OwnedPlanes3() = default;
  OwnedPlanes3(int w, int h) : pixels(3 * pixelsOf(w, h)) {
    const std::size_t n = pixelsOf(w, h);
    for (std::size_t c = 0; c < 3; ++c) {
      views[c] = viewOf(std::span<std::int16_t>(pixels).subspan(c * n, n), w, h);
    }
  }
};

// What interpolateDirections(), separate() and detectBoundaries() write for one projector.
struct ProjectorOut {
  OwnedPlanes3 separated;
  std::vector<std::uint8_t> order;
  std::vector<std::uint16_t> direction;
  std::vector<algo::Boundary> boundaries;

  ProjectorOut(int w, int h)
      : separated(w, h),
        order(pixelsOf(w, h)),
        direction(pixelsOf(w, h)),
        boundaries(pixelsOf(w, h)) {}
};

// The kernels of demux_kernels.hpp called one by one, as Demultiplexer::run() calls them, over
// buffers owned here.
class Stages {
 public:
  Stages(const algo::DemuxLayout& layout, std::span<const std::uint16_t> predicted)
      : kernels_(kern::fastestKernels()),
        layout_(layout),
        w_(layout.width),
        h_(layout.height),
        smoothed_(w_, h_),
        rowScratch_(kern::kSmoothRowScratch * static_cast<std::size_t>(w_)),
        tileSums_(layout.tileCount() * 3),
        tileInverse_(layout.tileCount() * 3),
        tileHistograms_(layout.tileCount() * kern::kBins),
        tileMoments_(layout.tileCount() * kern::kBins),
        predicted_(predicted.begin(), predicted.end()),
        tileDirections_(layout.tileCount() * static_cast<std::size_t>(layout.projectors)),
        tileScratch_(layout.tileCount()),
        columns_(static_cast<std::size_t>(w_)),
        rows_(static_cast<std::size_t>(h_)),
        filterMemory_(kern::RowBlock<std::int32_t>::valuesFor(kern::kFilterRows, w_)),
        filterRows_(filterMemory_, w_),
        workMemory_(kern::RowBlock<std::int16_t>::valuesFor(kern::kSharedWorkRows, w_)),
        workRows_(workMemory_, w_),
        strength_(pixelsOf(w_, h_)),
        derivativeStrength_(pixelsOf(w_, h_)),
        minStrength_(kern::minStrengthQ11(layout.params)) {
    units_.fill();
    kern::tileInterpolation(w_, layout.params.tilePx, layout.tilesX(), columns_);
    kern::tileInterpolation(h_, layout.params.tilePx, layout.tilesY(), rows_);
    projectors_.reserve(static_cast<std::size_t>(layout.projectors));
    for (int p = 0; p < layout.projectors; ++p) {
      projectors_.emplace_back(w_, h_);
    }
    for (std::size_t p = 0; p < projectors_.size(); ++p) {
      directionPlanes_[p] = viewOf(std::span(projectors_[p].direction), w_, h_);
      separatedPlanes_[p] = projectors_[p].separated.views;
      orderPlanes_[p] = viewOf(std::span(projectors_[p].order), w_, h_);
    }
  }

  void smooth(algo::ConstRgbView image) {
    kernels_.smooth(image, smoothed_.views, layout_.params.smoothPasses, rowScratch_);
  }
  void tileSums() { kern::sumTileColours(smoothed_.views, layout_.params.tilePx, tileSums_); }
  void tileInverse() {
    kern::inverseTileColours(tileSums_, layout_, layout_.params.normaliseColour, tileInverse_);
  }
  void histogram() {
    kernels_.histogram(smoothed_.views, layout_, filterRows_, tileHistograms_, tileMoments_, 0,
                       layout_.tilesY());
  }
  void directions() {
    kernels_.lobes(layout_, tileHistograms_, tileMoments_, predicted_, tileDirections_, 0,
                   layout_.tilesY());
    kernels_.finish(layout_, tileHistograms_, tileMoments_, predicted_, tileDirections_,
                    tileScratch_);
  }
  void interpolate() {
    kernels_.interpolation(layout_, tileDirections_, columns_, rows_, filterRows_,
                           directionPlanes(), {0, h_});
  }
  void separate() {
    kernels_.separation(smoothed_.views, layout_, tileDirections_, columns_, rows_, units_,
                        filterRows_, workRows_, directionPlanes(),
                        std::span(separatedPlanes_).first(projectors_.size()),
                        std::span(orderPlanes_).first(projectors_.size()), {0, h_});
  }
  void boundaries() {
    for (ProjectorOut& out : projectors_) {
      kernels_.boundaries(
          out.separated.views, viewOf(std::span<const std::uint8_t>(out.order), w_, h_),
          viewOf(std::span<const std::uint16_t>(out.direction), w_, h_), units_,
          {tileInverse_, layout_.tilesX(), columns_, rows_}, minStrength_, workRows_,
          {viewOf(std::span(strength_), w_, h_), viewOf(std::span(derivativeStrength_), w_, h_)},
          viewOf(std::span(out.boundaries), w_, h_));
    }
  }
  void all(algo::ConstRgbView image) {
    smooth(image);
    tileSums();
    tileInverse();
    histogram();
    directions();
    interpolate();
    separate();
    boundaries();
  }

  // The stage chain's output equals run()'s: the wiring above is the one timed by <cfg>/demux.
  [[nodiscard]] bool matches(const algo::Demultiplexer& d) const {
    for (int p = 0; p < layout_.projectors; ++p) {
      const ProjectorOut& mine = projectors_[static_cast<std::size_t>(p)];
      const algo::ConstBoundaryPlane b = d.boundaries(p);
      const algo::ConstDirectionPlane dir = d.directions(p);
      for (int y = 0; y < h_; ++y) {
        const std::size_t at = static_cast<std::size_t>(y) * static_cast<std::size_t>(w_);
        const auto rowBytes = static_cast<std::size_t>(w_);
        if (std::memcmp(b.rowPtr(y), &mine.boundaries[at], rowBytes * sizeof(algo::Boundary)) !=
                0 ||
            std::memcmp(dir.rowPtr(y), &mine.direction[at], rowBytes * sizeof(std::uint16_t)) !=
                0) {
          return false;
        }
      }
    }
    return true;
  }

 private:
  const kern::Kernels& kernels_;
  algo::DemuxLayout layout_;
  int w_;
  int h_;
  OwnedPlanes3 smoothed_;
  std::vector<std::int16_t> rowScratch_;
  std::vector<std::uint32_t> tileSums_;
  std::vector<std::uint32_t> tileInverse_;
  std::vector<std::uint32_t> tileHistograms_;
  std::vector<std::int32_t> tileMoments_;
  std::vector<std::uint16_t> predicted_;
  std::vector<algo::TileDirection> tileDirections_;
  std::vector<std::uint16_t> tileScratch_;
  std::vector<kern::TileInterp> columns_;
  std::vector<kern::TileInterp> rows_;
  kern::UnitTable units_;
  std::vector<std::int32_t> filterMemory_;
  kern::RowBlock<std::int32_t> filterRows_;
  std::vector<std::int16_t> workMemory_;
  kern::RowBlock<std::int16_t> workRows_;
  std::vector<std::uint16_t> strength_;
  std::vector<std::uint16_t> derivativeStrength_;
  std::vector<ProjectorOut> projectors_;
  std::array<algo::DirectionPlane, algo::kMaxProjectors> directionPlanes_{};
  std::array<kern::Planes3, algo::kMaxProjectors> separatedPlanes_{};
  std::array<algo::ImageView<std::uint8_t>, algo::kMaxProjectors> orderPlanes_{};
  int minStrength_;

  [[nodiscard]] std::span<const algo::DirectionPlane> directionPlanes() const {
    return std::span(directionPlanes_).first(projectors_.size());
  }
};

// One configuration: a rendered frame, the demultiplexer over its arena, the stage buffers and
// the start-up Sobel time. Not movable once built (the demultiplexer points into memory).
struct Config {
  std::string name;
  smx::eval::SimFrame frame;
  algo::DemuxLayout layout;
  std::size_t arenaBytes = 0;
  std::vector<std::byte> memory;
  std::unique_ptr<algo::Arena> arena;
  std::unique_ptr<algo::Demultiplexer> demux;
  std::vector<std::byte> baselineMemory;  // the same with DemuxSchedule::kBaseline
  std::unique_ptr<algo::Arena> baselineArena;
  std::unique_ptr<algo::Demultiplexer> baseline;
  std::unique_ptr<Stages> stages;
  // The whole pipeline of the same camera (demux, decode, triangulate, merge) over its own arena.
  std::size_t pipelineBytes = 0;
  std::vector<std::byte> pipelineMemory;
  std::unique_ptr<algo::Arena> pipelineArena;
  std::unique_ptr<algo::CameraPipeline> pipeline;
  // The same on two threads.
  std::size_t pipeline2Bytes = 0;
  std::vector<std::byte> pipeline2Memory;
  std::unique_ptr<algo::Arena> pipeline2Arena;
  std::unique_ptr<algo::CameraPipeline> pipeline2;
  smx::device::WorkerPool pool{1};
  cv::Mat sobelSrc;  // the frame, not copied
  cv::Mat sobelDst;
  double sobelSecondsPerCall = 0.0;  // thread CPU time
  double sobelWallSecondsPerCall = 0.0;

  [[nodiscard]] algo::ConstRgbView image() const { return frame.image.view(); }
  [[nodiscard]] double pixels() const {
    return static_cast<double>(pixelsOf(layout.width, layout.height));
  }
  void sobel() { cv::Sobel(sobelSrc, sobelDst, CV_16S, 1, 0, 3); }
  // Thread CPU seconds per Sobel call over `calls` calls.
  double sobelCpuPerCall(int calls) {
    const double cpu0 = threadCpuSeconds();
    for (int i = 0; i < calls; ++i) {
      sobel();
      benchmark::DoNotOptimize(sobelDst.data);
      benchmark::ClobberMemory();
    }
    return (threadCpuSeconds() - cpu0) / static_cast<double>(calls);
  }
};

// rig with camera 0 at twice the resolution (same field of view); projectors unchanged.
algo::Rig doubled(algo::Rig rig) {
  algo::Camera& cam = rig.cameras.at(0);
  cam.width *= 2;
  cam.height *= 2;
  cam.K[0] *= 2.0;                  // fx
  cam.K[4] *= 2.0;                  // fy
  cam.K[2] = 2.0 * cam.K[2] + 0.5;  // cx: pixel centres, (0,0) at the top-left pixel's
  cam.K[5] = 2.0 * cam.K[5] + 0.5;  // cy
  return rig;
}

// The example rig, with camera 0 at twice the size if `scaled`, and only its first
// `projectors` projectors when that is not 0.
algo::Rig benchRig(const std::string& rigFile, bool scaled, int projectors) {
  algo::Rig rig = smx::eval::loadExampleRig(rigFile);
  if (scaled) {
    rig = doubled(std::move(rig));
  }
  if (projectors > 0) {
    rig.projectors.resize(static_cast<std::size_t>(projectors));
  }
  return rig;
}

std::unique_ptr<Config> makeConfig(const std::string& rigFile, bool scaled, int keep = 0) {
  auto c = std::make_unique<Config>();
  const smx::eval::SimRequest request{rigFile, "plane"};
  const auto started = Clock::now();
  c->frame = smx::eval::renderSimFrame(benchRig(rigFile, scaled, keep),
                                       smx::eval::loadNamedScene("plane"), request);
  const double renderS = std::chrono::duration<double>(Clock::now() - started).count();
  const int w = c->frame.image.width;
  const int h = c->frame.image.height;
  const auto projectors = static_cast<int>(c->frame.rig.projectors.size());
  c->name = std::to_string(w) + "x" + std::to_string(h) + "_" + std::to_string(projectors) + "proj";
  c->layout = algo::DemuxLayout{w, h, projectors, {}};

  const auto bytes = algo::Demultiplexer::workspaceBytes(c->layout);
  if (!bytes) {
    die(c->name + ": workspaceBytes: " + bytes.error().message);
  }
  c->arenaBytes = *bytes;
  c->memory.resize(*bytes);
  c->arena = std::make_unique<algo::Arena>(c->memory);
  const auto predicted = algo::predictEncodingAngles(c->frame.rig, 0, c->layout, kNominalDepthM);
  if (!predicted) {
    die(c->name + ": predictEncodingAngles: " + predicted.error());
  }
  auto demux = algo::Demultiplexer::create(c->layout, *predicted, *c->arena);
  if (!demux) {
    die(c->name + ": create: " + demux.error().message);
  }
  c->demux = std::make_unique<algo::Demultiplexer>(std::move(*demux));
  c->baselineMemory.resize(*bytes);
  c->baselineArena = std::make_unique<algo::Arena>(c->baselineMemory);
  auto baseline = algo::Demultiplexer::create(c->layout, *predicted, *c->baselineArena,
                                              algo::DemuxSchedule::kBaseline);
  if (!baseline) {
    die(c->name + ": create (baseline): " + baseline.error().message);
  }
  c->baseline = std::make_unique<algo::Demultiplexer>(std::move(*baseline));
  if (!c->demux->run(c->image()) || !c->baseline->run(c->image())) {
    die(c->name + ": run failed");
  }
  c->stages = std::make_unique<Stages>(c->layout, *predicted);
  c->stages->all(c->image());
  if (!c->stages->matches(*c->demux)) {
    die(c->name + ": the stage chain's boundaries or directions differ from run()'s");
  }
  if (!c->stages->matches(*c->baseline)) {
    die(c->name + ": the baseline build's boundaries or directions differ from the AVX2 build's");
  }

  algo::PipelineOptions options;
  options.nominalDepthM = kNominalDepthM;
  const auto setup = algo::prepareCameraPipeline(c->frame.rig, 0, options);
  if (!setup) {
    die(c->name + ": prepareCameraPipeline: " + setup.error());
  }
  const auto pipelineBytes = algo::CameraPipeline::workspaceBytes(*setup);
  if (!pipelineBytes) {
    die(c->name + ": pipeline workspaceBytes: " + pipelineBytes.error().message);
  }
  c->pipelineBytes = *pipelineBytes;
  c->pipelineMemory.resize(*pipelineBytes);
  c->pipelineArena = std::make_unique<algo::Arena>(c->pipelineMemory);
  auto pipeline = algo::CameraPipeline::create(*setup, *c->pipelineArena);
  if (!pipeline || !pipeline->run(c->image())) {
    die(c->name + ": the pipeline cannot be created or run");
  }
  c->pipeline = std::make_unique<algo::CameraPipeline>(std::move(*pipeline));
  options.lanes = 2;
  const auto setup2 = algo::prepareCameraPipeline(c->frame.rig, 0, options);
  const auto pipeline2Bytes =
      setup2 ? algo::CameraPipeline::workspaceBytes(*setup2) : algo::Result<std::size_t>(0);
  if (!setup2 || !pipeline2Bytes) {
    die(c->name + ": the two-thread pipeline cannot be set up");
  }
  c->pipeline2Bytes = *pipeline2Bytes;
  c->pipeline2Memory.resize(*pipeline2Bytes);
  c->pipeline2Arena = std::make_unique<algo::Arena>(c->pipeline2Memory);
  auto pipeline2 = algo::CameraPipeline::create(*setup2, *c->pipeline2Arena);
  if (!pipeline2 || !pipeline2->run(c->image(), c->pool)) {
    die(c->name + ": the two-thread pipeline cannot be created or run");
  }
  c->pipeline2 = std::make_unique<algo::CameraPipeline>(std::move(*pipeline2));

  // The frame as an 8-bit, 3-channel Mat (the channel order does not matter to Sobel).
  c->sobelSrc = cv::Mat(h, w, CV_8UC3, c->frame.image.pixels.data(),
                        static_cast<std::size_t>(w) * sizeof(algo::Rgb8));
  for (int i = 0; i < kSobelWarmUp; ++i) {
    c->sobel();
  }
  const auto wall0 = Clock::now();
  c->sobelSecondsPerCall = c->sobelCpuPerCall(kSobelCalls);
  c->sobelWallSecondsPerCall =
      std::chrono::duration<double>(Clock::now() - wall0).count() / double{kSobelCalls};
  std::fprintf(stderr,
               "demux_bench: %s rendered in %.2f s; arena %zu bytes; Sobel %.4f ms CPU, %.4f ms "
               "wall\n",
               c->name.c_str(), renderS, c->arenaBytes, c->sobelSecondsPerCall * 1e3,
               c->sobelWallSecondsPerCall * 1e3);
  return c;
}

// Times body per iteration. x_sobel comes from the loop's own thread CPU time (a counter cannot
// read Google Benchmark's timer), which matches the CPU column to well under a per cent at
// these durations, over the Sobel reference taken around the loop.
template <class Body>
void timeFrames(benchmark::State& state, Config& c, std::size_t arenaBytes, const Body& body) {
  const double sobelBefore = c.sobelCpuPerCall(kLocalSobelCalls);
  const double cpu0 = threadCpuSeconds();
  for (auto _ : state) {
    body();
    benchmark::ClobberMemory();
  }
  const double seconds = threadCpuSeconds() - cpu0;
  const double sobelSeconds = (sobelBefore + c.sobelCpuPerCall(kLocalSobelCalls)) / 2;
  const auto frames = static_cast<double>(state.iterations());
  state.counters["px/s"] = benchmark::Counter(c.pixels() * frames, benchmark::Counter::kIsRate);
  state.counters["x_sobel"] = frames > 0 ? seconds / frames / sobelSeconds : 0.0;
  state.counters["sobel_ms"] = sobelSeconds * 1e3;
  state.counters["arena"] = benchmark::Counter(
      static_cast<double>(arenaBytes), benchmark::Counter::kDefaults, benchmark::Counter::kIs1024);
}

// Registers <cfg>/sobel, <cfg>/demux and the stages; c outlives the benchmarks.
void registerConfig(Config* c) {
  const auto addWith = [c](const std::string& what, std::size_t arenaBytes, auto body) {
    benchmark::RegisterBenchmark((c->name + "/" + what).c_str(), [c, arenaBytes,
                                                                  body](benchmark::State& s) {
      timeFrames(s, *c, arenaBytes, body);
    })->Unit(benchmark::kMillisecond);
  };
  const auto add = [c, addWith](const std::string& what, auto body) {
    addWith(what, c->arenaBytes, body);
  };
  Stages* st = c->stages.get();
  add("sobel", [c] { c->sobel(); });
  add("demux", [c] {
    auto ok = c->demux->run(c->image());
    benchmark::DoNotOptimize(ok);
  });
  add("demux_baseline", [c] {
    auto ok = c->baseline->run(c->image());
    benchmark::DoNotOptimize(ok);
  });
  add("1_smooth", [c, st] { st->smooth(c->image()); });
  add("2_tile_sums", [st] { st->tileSums(); });
  add("3_tile_inverse", [st] { st->tileInverse(); });
  add("4_histogram", [st] { st->histogram(); });
  add("5_directions", [st] { st->directions(); });
  add("6_interpolate", [st] { st->interpolate(); });
  add("7_separate", [st] { st->separate(); });
  add("8_boundaries", [st] { st->boundaries(); });
  // The whole frame through CameraPipeline, and its stages after demultiplexing (each repeats
  // on the previous stage's output of the last run()).
  algo::CameraPipeline* p = c->pipeline.get();
  addWith("pipeline", c->pipelineBytes, [c, p] {
    auto ok = p->run(c->image());
    benchmark::DoNotOptimize(ok);
  });
  addWith("p_decode", c->pipelineBytes, [p] {
    auto ok = p->decode();
    benchmark::DoNotOptimize(ok);
  });
  addWith("p_triangulate", c->pipelineBytes, [p] {
    auto ok = p->triangulate();
    benchmark::DoNotOptimize(ok);
  });
  addWith("p_merge", c->pipelineBytes, [p] {
    auto ok = p->merge();
    benchmark::DoNotOptimize(ok);
  });
  algo::CameraPipeline* p2 = c->pipeline2.get();
  addWith("pipeline_2threads", c->pipeline2Bytes, [c, p2] {
    auto ok = p2->run(c->image(), c->pool);
    benchmark::DoNotOptimize(ok);
  });
  addWith("p2_decode", c->pipeline2Bytes, [c, p2] {
    auto ok = p2->decode(c->pool);
    benchmark::DoNotOptimize(ok);
  });
  addWith("p2_triangulate", c->pipeline2Bytes, [c, p2] {
    auto ok = p2->triangulate(c->pool);
    benchmark::DoNotOptimize(ok);
  });
  addWith("p2_merge", c->pipeline2Bytes, [c, p2] {
    auto ok = p2->merge(c->pool);
    benchmark::DoNotOptimize(ok);
  });
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) {
    return 1;
  }
  // Single thread: OpenCV's parallel_for off, no OpenCL (Sobel on a Mat would not use it).
  cv::setNumThreads(1);
  cv::ocl::setUseOpenCL(false);

  std::vector<std::unique_ptr<Config>> configs;
  try {
    for (const bool scaled : {false, true}) {
      configs.push_back(makeConfig("rig_2proj_1cam.json", scaled, 1));
      for (const char* rig : {"rig_2proj_1cam.json", "rig_3proj_1cam.json"}) {
        configs.push_back(makeConfig(rig, scaled));
      }
    }
  } catch (const std::exception& e) {
    die(std::string("rendering the frames: ") + e.what());
  }

  benchmark::AddCustomContext("opencv", CV_VERSION);
  benchmark::AddCustomContext("opencv_threads", std::to_string(cv::getNumThreads()));
  benchmark::AddCustomContext(
      "demux_kernels", &kern::fastestKernels() == &kern::baselineKernels() ? "baseline" : "avx2");
  for (const auto& c : configs) {
    char ms[64];
    std::snprintf(ms, sizeof ms, "%.4f CPU, %.4f wall", c->sobelSecondsPerCall * 1e3,
                  c->sobelWallSecondsPerCall * 1e3);
    benchmark::AddCustomContext("sobel_ms_" + c->name, ms);
    registerConfig(c.get());
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
