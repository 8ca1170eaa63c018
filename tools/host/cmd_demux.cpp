// stripemux demux --rig rig.json --image CAM=FILE [--image CAM=FILE ...] [--debug DIR]
//                 [--nominal-depth M]
// Runs orientation demultiplexing on camera images and reports, per camera and projector, what
// it found; --debug writes the stripe-segmentation renderings (docs/cli.md, docs/demux.md).
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "camera_images.hpp"
#include "commands.hpp"
#include "demux_debug.hpp"
#include "output_folder.hpp"
#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/demux.hpp"
#include "smx/algo/encoding_prediction.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

struct DemuxOptions {
  fs::path rig;
  std::vector<std::string> images;  // CAM=FILE
  std::optional<fs::path> debug;
  double nominalDepthM = algo::kDefaultNominalDepthM;
};

int runDemux(const DemuxOptions& opts, const CliStreams& io) {
  const auto fail = [&](int code, const std::string& message) {
    io.err << "stripemux demux: " << message << "\n";
    return code;
  };
  const auto loaded = loadRigAndImages(opts.rig, opts.images);
  if (!loaded) {
    return fail(kExitBadInput, loaded.error());
  }
  const algo::Rig* rig = &loaded->rig;
  const std::vector<CameraImage>* images = &loaded->images;
  std::optional<OutputFolder> debug;
  if (opts.debug) {
    auto folder = OutputFolder::create(*opts.debug);
    if (!folder) {
      return fail(kExitDeviceOrIo, folder.error());
    }
    debug.emplace(std::move(*folder));
  }
  // Printed once the files are in place.
  std::ostringstream report;
  for (const auto& [cameraIndex, file] : *images) {
    const algo::Camera& camera = rig->cameras[cameraIndex];
    const auto image = readCameraImage(file, camera);
    if (!image) {
      return fail(kExitBadInput, image.error());
    }
    if (auto colour = checkHasColour(file, *image); !colour) {
      return fail(kExitBadInput, colour.error());
    }
    const algo::DemuxLayout layout{
        camera.width, camera.height, static_cast<int>(rig->projectors.size()), {}};
    const auto predicted = algo::predictEncodingAngles(*rig, static_cast<int>(cameraIndex), layout,
                                                       opts.nominalDepthM);
    if (!predicted) {
      return fail(kExitBadInput, opts.rig.string() + ": " + predicted.error());
    }
    const auto bytes = algo::Demultiplexer::workspaceBytes(layout);
    if (!bytes) {
      return fail(kExitBadInput, bytes.error().message);
    }
    std::vector<std::byte> memory(*bytes);
    algo::Arena arena(memory);
    auto demux = algo::Demultiplexer::create(layout, *predicted, arena);
    if (!demux) {
      return fail(kExitBadInput, demux.error().message);
    }
    const auto start = std::chrono::steady_clock::now();
    if (auto ok = demux->run(image->view()); !ok) {
      return fail(kExitBadInput, file.string() + ": " + ok.error().message);
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    report << camera.id << " (" << file.string() << "): demultiplexed in " << static_cast<int>(ms)
           << " ms, " << *bytes / 1024 << " KiB working memory\n";
    for (int p = 0; p < layout.projectors; ++p) {
      const auto& projector = rig->projectors[static_cast<std::size_t>(p)];
      std::size_t boundaries = 0;
      const auto plane = demux->boundaries(p);
      for (int y = 0; y < plane.height(); ++y) {
        for (int x = 0; x < plane.width(); ++x) {
          boundaries += plane(x, y).present() ? 1U : 0U;
        }
      }
      std::size_t present = 0;
      for (const auto& tile : demux->tileDirections(p)) {
        present += tile.present;
      }
      report << "  " << projector.id << ": " << boundaries << " boundary pixels, pattern found in "
             << (100 * present) / layout.tileCount() << " % of the image\n";
      if (debug) {
        const std::string tag = projector.id + "." + camera.id;
        if (auto ok = writeDemuxDebug(*debug, tag, *demux, p); !ok) {
          return fail(kExitDeviceOrIo, ok.error());
        }
        report << "    wrote "
               << debug->pathOf(tag + ".{boundaries,separated,direction}.png").string() << "\n";
      }
    }
  }
  if (auto ok = debug ? debug->commit() : std::expected<void, std::string>{}; !ok) {
    return fail(kExitDeviceOrIo, ok.error());
  }
  io.out << report.str();
  return kExitOk;
}

}  // namespace

void addDemuxCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<DemuxOptions>();
  auto* cmd = app.add_subcommand(
      "demux",
      "Separate the superposed projector patterns in camera images and find their stripes");
  cmd->add_option("--rig", opts->rig, "Rig description (stripemux-rig/1 JSON)")->required();
  cmd->add_option("--image", opts->images, "CAMERA=FILE: a camera's image (PNG), repeatable")
      ->required();
  cmd->add_option("--debug", opts->debug,
                  "Write per projector and camera: boundaries, separated derivative, direction");
  cmd->add_option("--nominal-depth", opts->nominalDepthM,
                  "Depth (m) at which the rig predicts the pattern directions")
      ->check(CLI::Range(0.05, 100.0));
  cmd->callback([opts, &io, &exitCode] { exitCode = runDemux(*opts, io); });
}

}  // namespace smx::host
