// stripemux decode --rig rig.json --image CAM=FILE [--image CAM=FILE ...] --out DIR
//                  [--debug DIR2] [--nominal-depth M] [--depth-unit M]
// The whole offline pipeline on camera images: demultiplexing, decoding, triangulation, merging;
// range images, point clouds and meta.json (docs/cli.md, docs/decode.md).
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "camera_images.hpp"
#include "command_failure.hpp"
#include "commands.hpp"
#include "decode_debug.hpp"
#include "demux_debug.hpp"
#include "output_files.hpp"
#include "point_cloud.hpp"
#include "smx/algo/camera_pipeline.hpp"
#include "smx/sim/ply_io.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;
using OrderedJson = nlohmann::ordered_json;

struct DecodeOptions {
  fs::path rig;
  std::vector<std::string> images;  // CAM=FILE
  fs::path out;
  std::optional<fs::path> debug;
  double nominalDepthM = algo::kDefaultNominalDepthM;
  double depthUnitM = algo::kDefaultDepthUnitM;
};

// A failure with its exit code and message.
int countValid(algo::ConstDepthPlane depth) {
  int n = 0;
  for (int y = 0; y < depth.height(); ++y) {
    for (int x = 0; x < depth.width(); ++x) {
      n += depth(x, y) != algo::kNoDepth ? 1 : 0;
    }
  }
  return n;
}

// Depths beyond 65535 units are lost; a unit that cannot store the working range is refused.
std::string depthUnitProblem(const DecodeOptions& opts) {
  std::ostringstream s;
  s << "--depth-unit " << opts.depthUnitM << ": 16-bit depth images in that unit store depths up "
    << "to " << algo::maxStoredDepthM(opts.depthUnitM) << " m, and every depth beyond is lost; "
    << "the rig works at " << opts.nominalDepthM << " m (--nominal-depth), so depths to "
    << algo::kWorkingRangeFactor * opts.nominalDepthM << " m must fit: use --depth-unit "
    << algo::minDepthUnitM(opts.nominalDepthM) << " or more";
  return s.str();
}

std::expected<void, CommandFailure> writeOrFail(const std::expected<void, std::string>& written) {
  if (!written) {
    return std::unexpected(CommandFailure{kExitDeviceOrIo, written.error()});
  }
  return {};
}

std::expected<void, CommandFailure> writeDebug(OutputFolder& dir, const algo::Camera& camera,
                                               const algo::Rig& rig,
                                               algo::CameraPipeline& pipeline) {
  for (int p = 0; p < pipeline.projectors(); ++p) {
    const std::string tag = rig.projectors[static_cast<std::size_t>(p)].id + "." + camera.id;
    if (auto ok = writeOrFail(writeDemuxDebug(dir, tag, pipeline.demux(), p)); !ok) {
      return ok;
    }
    if (auto ok = writeOrFail(
            writePngRgb8(dir, tag + ".stripes.png", renderStripes(pipeline.stripe(p)).view()));
        !ok) {
      return ok;
    }
    if (auto ok = writeOrFail(
            writePngRgb8(dir, tag + ".depth.png", renderDepth(pipeline.depth(p)).view()));
        !ok) {
      return ok;
    }
  }
  return writeOrFail(
      writePngRgb8(dir, camera.id + ".depth.png", renderDepth(pipeline.merged()).view()));
}

// The output folders of a run: --out, and --debug when given.
struct Outputs {
  OutputFolder out;
  std::optional<OutputFolder> debug;
};

// Runs one camera's image through the pipeline, writes its files, and appends its meta.json entry
// to `cameras` and its world points to `merged`.
std::expected<void, CommandFailure> decodeCamera(const DecodeOptions& opts, const algo::Rig& rig,
                                                 const CameraImage& input, std::ostream& report,
                                                 Outputs& outputs, OrderedJson& cameras,
                                                 std::vector<sim::PlyPoint>& merged) {
  const algo::Camera& camera = rig.cameras[input.camera];
  const auto image = readCameraImage(input.file, camera);
  if (!image) {
    return std::unexpected(CommandFailure{kExitBadInput, image.error()});
  }
  if (auto colour = checkHasColour(input.file, *image); !colour) {
    return std::unexpected(CommandFailure{kExitBadInput, colour.error()});
  }
  algo::PipelineOptions options;
  options.nominalDepthM = opts.nominalDepthM;
  options.depthUnitM = opts.depthUnitM;
  const auto setup = algo::prepareCameraPipeline(rig, static_cast<int>(input.camera), options);
  if (!setup) {
    return std::unexpected(CommandFailure{kExitBadInput, opts.rig.string() + ": " + setup.error()});
  }
  const auto bytes = algo::CameraPipeline::workspaceBytes(*setup);
  if (!bytes) {
    return std::unexpected(CommandFailure{kExitBadInput, bytes.error().message});
  }
  std::vector<std::byte> memory(*bytes);
  algo::Arena arena(memory);
  auto pipeline = algo::CameraPipeline::create(*setup, arena);
  if (!pipeline) {
    return std::unexpected(CommandFailure{kExitBadInput, pipeline.error().message});
  }

  // The stages one by one, timed.
  OrderedJson timings = OrderedJson::object();
  double totalMs = 0;
  const auto timed = [&](const char* name, auto&& stage) -> algo::Result<void> {
    const auto start = std::chrono::steady_clock::now();
    auto ok = stage();
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    timings[name] = ms;
    totalMs += ms;
    return ok;
  };
  algo::Result<void> ok = timed("demux", [&] { return pipeline->demultiplex(image->view()); });
  ok = ok ? timed("decode", [&] { return pipeline->decode(); }) : ok;
  ok = ok ? timed("triangulate", [&] { return pipeline->triangulate(); }) : ok;
  ok = ok ? timed("merge", [&] { return pipeline->merge(); }) : ok;
  if (!ok) {
    return std::unexpected(
        CommandFailure{kExitBadInput, input.file.string() + ": " + ok.error().message});
  }
  timings["total"] = totalMs;

  OrderedJson pairs = OrderedJson::array();
  for (int p = 0; p < pipeline->projectors(); ++p) {
    const std::string name =
        rig.projectors[static_cast<std::size_t>(p)].id + "." + camera.id + ".depth.png";
    if (auto w = writeOrFail(writePngGray16(outputs.out, name, pipeline->depth(p))); !w) {
      return std::unexpected(w.error());
    }
    const algo::DecodeStats& stats = pipeline->decodeStats(p);
    pairs.push_back({{"projector", rig.projectors[static_cast<std::size_t>(p)].id},
                     {"depth", name},
                     {"valid_pixels", countValid(pipeline->depth(p))},
                     {"boundary_pixels", stats.boundaryPixels},
                     {"decoded_boundary_pixels", stats.decodedPixels}});
  }
  const std::string depthName = depthPngName(camera.id);
  if (auto w = writeOrFail(writePngGray16(outputs.out, depthName, pipeline->merged())); !w) {
    return std::unexpected(w.error());
  }
  const std::string confidenceName = confidencePngName(camera.id);
  if (auto w = writeOrFail(writePngGray8(outputs.out, confidenceName, pipeline->confidence()));
      !w) {
    return std::unexpected(w.error());
  }
  const auto points =
      depthToWorldPoints(camera, pipeline->merged(), opts.depthUnitM, image->view());
  const std::string plyName = camera.id + ".ply";
  if (auto w = writeOrFail(writePlyPoints(outputs.out, plyName, points)); !w) {
    return std::unexpected(w.error());
  }
  if (outputs.debug) {
    if (auto w = writeDebug(*outputs.debug, camera, rig, *pipeline); !w) {
      return std::unexpected(w.error());
    }
  }
  const int valid = countValid(pipeline->merged());
  report << camera.id << " (" << input.file.string() << "): " << valid << " depth pixels ("
         << (100 * valid) / (camera.width * camera.height) << " % of the image) in "
         << static_cast<int>(totalMs) << " ms, " << *bytes / 1024 << " KiB working memory\n";
  for (const auto& pair : pairs) {
    report << "  " << pair["projector"].get<std::string>() << ": "
           << pair["valid_pixels"].get<int>() << " depth pixels\n";
  }
  merged.insert(merged.end(), points.begin(), points.end());
  cameras.push_back({{"id", camera.id},
                     {"image", input.file.string()},
                     {"width", camera.width},
                     {"height", camera.height},
                     {"depth", depthName},
                     {"confidence", confidenceName},
                     {"ply", plyName},
                     {"valid_pixels", valid},
                     {"working_memory_bytes", *bytes},
                     {"timings_ms", timings},
                     {"pairs", pairs}});
  return {};
}

int runDecode(const DecodeOptions& opts, const CliStreams& io) {
  const auto fail = [&](int code, const std::string& message) {
    io.err << "stripemux decode: " << message << "\n";
    return code;
  };
  if (opts.depthUnitM < algo::minDepthUnitM(opts.nominalDepthM)) {
    return fail(kExitUsage, depthUnitProblem(opts));
  }
  const auto loaded = loadRigAndImages(opts.rig, opts.images);
  if (!loaded) {
    return fail(kExitBadInput, loaded.error());
  }
  auto out = OutputFolder::create(opts.out);
  if (!out) {
    return fail(kExitDeviceOrIo, out.error());
  }
  Outputs outputs{std::move(*out), std::nullopt};
  if (opts.debug) {
    auto debug = OutputFolder::create(*opts.debug);
    if (!debug) {
      return fail(kExitDeviceOrIo, debug.error());
    }
    outputs.debug.emplace(std::move(*debug));
  }
  OrderedJson cameras = OrderedJson::array();
  std::vector<sim::PlyPoint> merged;
  std::ostringstream report;
  for (const CameraImage& input : loaded->images) {
    if (auto ok = decodeCamera(opts, loaded->rig, input, report, outputs, cameras, merged); !ok) {
      return fail(ok.error().code, ok.error().message);
    }
  }
  if (auto ok = writePlyPoints(outputs.out, "merged.ply", merged); !ok) {
    return fail(kExitDeviceOrIo, ok.error());
  }
  const OrderedJson meta = {{"format", "stripemux-decode/1"}, {"depth_unit_m", opts.depthUnitM},
                            {"rig", opts.rig.string()},       {"cameras", cameras},
                            {"merged_ply", "merged.ply"},     {"merged_points", merged.size()}};
  if (auto ok = outputs.out.writeText(
          "meta.json", meta.dump(2, ' ', false, OrderedJson::error_handler_t::replace) + "\n");
      !ok) {
    return fail(kExitDeviceOrIo, ok.error());
  }
  if (auto ok = outputs.out.commit(); !ok) {
    return fail(kExitDeviceOrIo, ok.error());
  }
  if (auto ok = outputs.debug ? outputs.debug->commit() : std::expected<void, std::string>{}; !ok) {
    return fail(kExitDeviceOrIo, ok.error());
  }
  io.out << report.str() << "wrote " << outputs.out.pathOf("merged.ply").string() << " ("
         << merged.size() << " points) and " << outputs.out.pathOf("meta.json").string() << "\n";
  return kExitOk;
}

}  // namespace

void addDecodeCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<DecodeOptions>();
  auto* cmd = app.add_subcommand(
      "decode", "Range images and point clouds from camera images: the whole offline pipeline");
  cmd->add_option("--rig", opts->rig, "Rig description (stripemux-rig/1 JSON)")->required();
  cmd->add_option("--image", opts->images, "CAMERA=FILE: a camera's image (PNG), repeatable")
      ->required();
  cmd->add_option("--out", opts->out,
                  "Output directory: depth and confidence PNGs, PLY point clouds, meta.json")
      ->required();
  cmd->add_option("--debug", opts->debug,
                  "Write per projector and camera: stripe segmentation, decoded stripes, depth");
  cmd->add_option(
         "--nominal-depth", opts->nominalDepthM,
         "Depth (m) at which the rig predicts the pattern directions; depth is kept from half "
         "to twice it")
      ->check(CLI::Range(0.05, 100.0));
  cmd->add_option("--depth-unit", opts->depthUnitM,
                  "Metres per unit of the 16-bit depth images (default 0.0001)")
      ->check(CLI::Range(1e-6, 0.01));
  cmd->callback([opts, &io, &exitCode] { exitCode = runDecode(*opts, io); });
}

}  // namespace smx::host
