// pipeline_frames --rig RIG.json --image FRAME.ppm --frames N [--until STAGE] [--reference]: one
// camera's pipeline, set up as the firmware sets it up (Device::create), run N times on one frame.
// Built for every preset; tests/armcost/count-instructions runs the aarch64 build under qemu-user
// with an instruction-counting plugin and subtracts a --frames 0 run, which does all the same
// set-up and no frame (docs/arm-cost.md). --until stops each frame after a stage, for the split:
// demux, decode, triangulate, merge (the whole pipeline: CameraPipeline::run, the default) or
// send (merge, then the range frame encoded for the wire with RVL, as while streaming).
// Exit codes: 0 ok, 1 usage, 2 rejected rig or image, 3 the pipeline failed.
#include <CLI/CLI.hpp>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <expected>
#include <fstream>
#include <istream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "ppm_io.hpp"
#include "smx/algo/camera_pipeline.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/protocol/messages.hpp"

namespace {

using namespace smx;

constexpr int kExitBadInput = 2;
constexpr int kExitPipeline = 3;

enum class Stage : std::uint8_t { kDemux, kDecode, kTriangulate, kMerge, kSend };

struct Options {
  std::string rig;
  std::string image;
  int frames = 1;
  Stage until = Stage::kMerge;
  bool reference = false;
};

// Pixels with a result, counted without branches so that a run of 0 frames (over zeroed planes)
// executes the same instructions as a run of N.
template <class Pixel, class Has>
std::int64_t countPixels(algo::ImageView<const Pixel> plane, Has has) {
  std::int64_t count = 0;
  for (int y = 0; y < plane.height(); ++y) {
    for (const Pixel& p : plane.row(y)) {
      count += static_cast<std::int64_t>(has(p));
    }
  }
  return count;
}

// What the last stage produced, so that the output depends on every frame's work.
std::pair<std::int64_t, const char*> lastStageResult(const algo::CameraPipeline& pipeline,
                                                     Stage until) {
  const auto hasDepth = [](std::uint16_t d) { return d != algo::kNoDepth; };
  std::int64_t result = 0;
  switch (until) {
    case Stage::kDemux:
      for (int p = 0; p < pipeline.projectors(); ++p) {
        result += countPixels(pipeline.demux().boundaries(p),
                              [](const algo::Boundary& b) { return b.present(); });
      }
      return {result, "boundary pixels"};
    case Stage::kDecode:
      for (int p = 0; p < pipeline.projectors(); ++p) {
        result += pipeline.decodeStats(p).densePixels;
      }
      return {result, "decoded pixels"};
    case Stage::kTriangulate:
      for (int p = 0; p < pipeline.projectors(); ++p) {
        result += countPixels(pipeline.depth(p), hasDepth);
      }
      return {result, "depth pixels over all projectors"};
    case Stage::kMerge:
    case Stage::kSend:
      break;
  }
  return {countPixels(pipeline.merged(), hasDepth), "merged depth pixels"};
}

int run(const Options& opts) {
  auto rig = config::loadRig(opts.rig);
  if (!rig) {
    std::fprintf(stderr, "pipeline_frames: %s\n", rig.error().message().c_str());
    return kExitBadInput;
  }
  auto image = test::readPpm(opts.image);
  if (!image) {
    std::fprintf(stderr, "pipeline_frames: %s\n", image.error().c_str());
    return kExitBadInput;
  }
  const algo::Camera& camera = rig->cameras.front();
  if (image->width != camera.width || image->height != camera.height) {
    std::fprintf(stderr, "pipeline_frames: %s is %dx%d but camera %s of %s is %dx%d\n",
                 opts.image.c_str(), image->width, image->height, camera.id.c_str(),
                 opts.rig.c_str(), camera.width, camera.height);
    return kExitBadInput;
  }
  const auto view = algo::ConstRgbView::packed(image->pixels, image->width, image->height);
  if (!view) {
    std::fprintf(stderr, "pipeline_frames: %s: %s\n", opts.image.c_str(), view.error().message);
    return kExitBadInput;
  }

  // As Device::create: default options, the depth unit of the board (every board in boards/
  // has 0.0001 m, the default), one arena per camera sized by workspaceBytes().
  const algo::PipelineOptions options;
  const auto setup = algo::prepareCameraPipeline(*rig, 0, options);
  if (!setup) {
    std::fprintf(stderr, "pipeline_frames: %s: camera %s: %s\n", opts.rig.c_str(),
                 camera.id.c_str(), setup.error().c_str());
    return kExitBadInput;
  }
  const auto bytes = algo::CameraPipeline::workspaceBytes(*setup);
  if (!bytes) {
    std::fprintf(stderr, "pipeline_frames: %s\n", bytes.error().message);
    return kExitPipeline;
  }
  std::vector<std::byte> memory(*bytes);
  algo::Arena arena(memory);
  auto pipeline = algo::CameraPipeline::create(*setup, arena);
  if (!pipeline) {
    std::fprintf(stderr, "pipeline_frames: %s\n", pipeline.error().message);
    return kExitPipeline;
  }
  pipeline->useReferenceKernels(opts.reference);
  // The send queue's slot size (Device's constructor); fixed header fields keep runs identical.
  std::vector<std::byte> wire(protocol::rangeFrameBound(camera.width, camera.height));
  const protocol::RangeFrameHeader header{
      .camera = 0,
      .compression = protocol::Compression::kRvl,
      .frame = 0,
      .captureTimestampNs = 0,
      .sentTimestampNs = 0,
      .depthUnitNm = static_cast<std::uint32_t>(std::lround(options.depthUnitM * 1e9)),
      .decodeTimeUs = 0};

  std::size_t wireBytes = 0;
  for (int frame = 0; frame < opts.frames; ++frame) {
    algo::Result<void> ok;
    if (opts.until >= Stage::kMerge) {
      ok = pipeline->run(*view);  // the firmware's call (Device::decodeCamera)
    } else {
      ok = pipeline->demultiplex(*view);
      if (ok && opts.until >= Stage::kDecode) {
        ok = pipeline->decode();
      }
      if (ok && opts.until >= Stage::kTriangulate) {
        ok = pipeline->triangulate();
      }
    }
    if (!ok) {
      std::fprintf(stderr, "pipeline_frames: frame %d: %s\n", frame, ok.error().message);
      return kExitPipeline;
    }
    if (opts.until == Stage::kSend) {
      const auto message = protocol::encodeRangeFrame(header, pipeline->merged(), wire);
      if (!message) {
        std::fprintf(stderr, "pipeline_frames: frame %d: encoding: %s\n", frame,
                     message.error().message);
        return kExitPipeline;
      }
      wireBytes = message->size();
    }
  }

  const auto [result, what] = lastStageResult(*pipeline, opts.until);
  const int projectors = pipeline->projectors();
  std::printf("%d frames of %dx%d, %d projector%s: %lld %s", opts.frames, camera.width,
              camera.height, projectors, projectors == 1 ? "" : "s", static_cast<long long>(result),
              what);
  if (opts.until == Stage::kSend) {
    std::printf(", %zu bytes on the wire", wireBytes);
  }
  std::printf("\n");
  return 0;
}

int parseAndRun(int argc, char** argv) {
  CLI::App app{"pipeline_frames: one camera's pipeline run N times on one frame"};
  Options opts;
  app.add_option("--rig", opts.rig, "Rig (stripemux-rig/1 JSON); its first camera is used")
      ->required();
  app.add_option("--image", opts.image, "The camera's frame as a binary PPM (P6, 8 bits)")
      ->required();
  app.add_option("--frames", opts.frames, "Frames to run (0: set-up only)")
      ->check(CLI::Range(0, 1'000'000));
  const std::map<std::string, Stage> stages{{"demux", Stage::kDemux},
                                            {"decode", Stage::kDecode},
                                            {"triangulate", Stage::kTriangulate},
                                            {"merge", Stage::kMerge},
                                            {"send", Stage::kSend}};
  std::string until = "merge";
  app.add_option("--until", until,
                 "Last stage of each frame: demux, decode, triangulate, merge "
                 "(the whole pipeline, default) or send (merge + RVL encoding)")
      ->check(CLI::IsMember({"demux", "decode", "triangulate", "merge", "send"}));
  app.add_flag("--reference", opts.reference,
               "Every stage after demultiplexing as its plain scalar definition, not its schedule");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;
  }
  opts.until = stages.at(until);
  return run(opts);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return parseAndRun(argc, argv);
  } catch (const std::exception& e) {  // out of memory while setting up
    std::fprintf(stderr, "pipeline_frames: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "pipeline_frames: unexpected error\n");
  }
  return kExitPipeline;
}
