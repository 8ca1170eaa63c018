// stripemux check --rig RIG.json --images DIR [--report DIR2] [--json]
// stripemux check --device HOST[:PORT] [--report DIR2] [--json]
// The rig's health check on one frame with every projector lit: DIR/<cam>.png per camera (as
// `stripemux sim` writes them) or a raw capture from the device, checked with its rig; per
// projector a verdict, good / drifted / not enough overlap (docs/health-check.md, docs/cli.md).
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "camera_images.hpp"
#include "commands.hpp"
#include "device_client.hpp"
#include "device_option.hpp"
#include "output_folder.hpp"
#include "smx/health/check.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;
using OrderedJson = nlohmann::ordered_json;

// The check ran and a projector is not good (docs/cli.md).
constexpr int kExitNotHealthy = 4;

// How long the device may take for the raw capture: it first finishes the frame in hand, and a
// board decoding two cameras may take seconds for that.
constexpr auto kCaptureTimeout = std::chrono::milliseconds(30'000);

struct CheckOptions {
  fs::path rig;
  fs::path images;
  std::string device;
  std::optional<fs::path> report;
  bool json = false;
};

const char* kindName(health::Comparison::Kind kind) {
  return kind == health::Comparison::Kind::kProjectorPair ? "projector_pair" : "camera_pair";
}

OrderedJson toJson(const algo::Rig& rig, const health::CheckReport& report) {
  OrderedJson projectors = OrderedJson::array();
  for (const auto& h : report.projectors) {
    projectors.push_back({{"id", h.id},
                          {"verdict", health::verdictName(h.verdict)},
                          {"disagreement_mm", h.disagreementMm},
                          {"reason", h.reason}});
  }
  OrderedJson comparisons = OrderedJson::array();
  for (const auto& c : report.comparisons) {
    const auto& d = c.disagreement;
    OrderedJson j = {{"kind", kindName(c.kind)},
                     {"camera", rig.cameras[static_cast<std::size_t>(c.camera)].id}};
    if (c.kind == health::Comparison::Kind::kProjectorPair) {
      j["projectors"] = {rig.projectors[static_cast<std::size_t>(c.projector)].id,
                         rig.projectors[static_cast<std::size_t>(c.otherProjector)].id};
    } else {
      j["projector"] = rig.projectors[static_cast<std::size_t>(c.projector)].id;
      j["other_camera"] = rig.cameras[static_cast<std::size_t>(c.otherCamera)].id;
    }
    j["pixels"] = d.pixels;
    j["blocks"] = d.blocks;
    j["enough_overlap"] = d.enough;
    if (d.enough) {
      j["offset_mm"] = d.offsetMm;
      j["slope_x_mm"] = d.slopeXMm;
      j["slope_y_mm"] = d.slopeYMm;
      j["sigma_mm"] = d.sigmaMm;
      j["systematic_mm"] = d.systematicMm;
      j["threshold_mm"] = d.thresholdMm;
      j["disagrees"] = d.disagrees;
    }
    if (c.shapeFitted) {
      j["pose_fit_residual_mm"] = c.shapeResidualMm;
    }
    comparisons.push_back(j);
  }
  return {{"format", "stripemux-check/1"},
          {"healthy", report.healthy},
          {"summary", report.summary},
          {"projectors", projectors},
          {"comparisons", comparisons}};
}

std::string toText(const health::CheckReport& report) {
  std::ostringstream s;
  for (const auto& h : report.projectors) {
    s << h.id << ": " << health::verdictName(h.verdict);
    if (h.verdict != health::Verdict::kNoOverlap) {
      s.setf(std::ios::fixed);
      s.precision(2);
      s << " (" << h.disagreementMm << " mm)";
    }
    s << " — " << h.reason << "\n";
  }
  s << report.summary << "\n";
  return s.str();
}

int checkFailed(const CliStreams& io, int code, const std::string& message) {
  io.err << "stripemux check: " << message << "\n";
  return code;
}

// The check of `frames` with `rig` (named `rigName` in errors), printed and written.
int checkAndReport(const algo::Rig& rig, const std::string& rigName,
                   const std::vector<health::CameraFrame>& frames, const CheckOptions& opts,
                   const CliStreams& io) {
  const auto report = health::checkRig(rig, frames);
  if (!report) {
    return checkFailed(io, kExitBadInput, rigName + ": " + report.error());
  }
  const OrderedJson json = toJson(rig, *report);
  const std::string jsonText =
      json.dump(2, ' ', false, OrderedJson::error_handler_t::replace) + "\n";
  if (opts.report) {
    auto out = OutputFolder::create(*opts.report);
    if (!out) {
      return checkFailed(io, kExitDeviceOrIo, out.error());
    }
    if (auto ok = out->writeText("check.json", jsonText); !ok) {
      return checkFailed(io, kExitDeviceOrIo, ok.error());
    }
    if (auto ok = out->writeText("check.txt", toText(*report)); !ok) {
      return checkFailed(io, kExitDeviceOrIo, ok.error());
    }
    if (auto ok = out->commit(); !ok) {
      return checkFailed(io, kExitDeviceOrIo, ok.error());
    }
  }
  io.out << (opts.json ? jsonText : toText(*report));
  return report->healthy ? kExitOk : kExitNotHealthy;
}

int runCheck(const CheckOptions& opts, const CliStreams& io) {
  // One image per camera that has one in the folder; loadRigAndImages checks the rig and them.
  auto rigOnly = loadRigAndImages(opts.rig, {});
  if (!rigOnly) {
    return checkFailed(io, kExitBadInput, rigOnly.error());
  }
  std::vector<std::string> specs;
  for (const auto& camera : rigOnly->rig.cameras) {
    const fs::path file = opts.images / (camera.id + ".png");
    std::error_code ec;
    if (fs::exists(file, ec)) {
      specs.push_back(camera.id + "=" + file.string());
    }
  }
  if (specs.empty()) {
    return checkFailed(io, kExitBadInput,
                       opts.images.string() + ": no camera image (expected " +
                           rigOnly->rig.cameras.front().id + ".png and one per camera)");
  }
  const auto loaded = loadRigAndImages(opts.rig, specs);
  if (!loaded) {
    return checkFailed(io, kExitBadInput, loaded.error());
  }
  std::vector<sim::RgbImage> images;
  for (const CameraImage& input : loaded->images) {
    auto image = readCameraImage(input.file, loaded->rig.cameras[input.camera]);
    if (!image) {
      return checkFailed(io, kExitBadInput, image.error());
    }
    if (auto colour = checkHasColour(input.file, *image); !colour) {
      return checkFailed(io, kExitBadInput, colour.error());
    }
    images.push_back(std::move(*image));
  }
  std::vector<health::CameraFrame> frames;
  for (std::size_t i = 0; i < images.size(); ++i) {
    frames.push_back({loaded->images[i].camera, images[i].view()});
  }
  return checkAndReport(loaded->rig, opts.rig.string(), frames, opts, io);
}

// One raw capture with every projector lit, checked with the rig the device announces.
int runDeviceCheck(const CheckOptions& opts, const CliStreams& io) {
  auto client = DeviceClient::connect(opts.device, kDeviceConnectTimeout);
  if (!client) {
    return checkFailed(io, kExitDeviceOrIo, client.error());
  }
  const algo::Rig& rig = client->info().rig;
  const std::string rigName = client->info().address + ": the device's rig";
  if (rig.cameras.empty() || rig.projectors.empty() || rig.projectors.size() > 32) {
    return checkFailed(io, kExitBadInput,
                       rigName + ": the check needs a camera and 1 to 32 projectors");
  }
  const std::uint32_t all = rig.projectors.size() == 32 ? ~0U : (1U << rig.projectors.size()) - 1U;
  const auto capture = client->captureRaw(all, kCaptureTimeout);
  client->close();
  if (!capture) {
    return checkFailed(io, kExitDeviceOrIo, client->info().address + ": " + capture.error());
  }
  std::vector<health::CameraFrame> frames;
  for (std::size_t c = 0; c < rig.cameras.size() && c < capture->images.size(); ++c) {
    const auto& camera = rig.cameras[c];
    const auto view =
        algo::ConstRgbView::packed(capture->images[c], capture->width, capture->height);
    if (!view || capture->width != camera.width || capture->height != camera.height) {
      return checkFailed(io, kExitDeviceOrIo,
                         client->info().address + ": " + camera.id + " sent " +
                             std::to_string(capture->width) + "x" +
                             std::to_string(capture->height) + ", its rig says " +
                             std::to_string(camera.width) + "x" + std::to_string(camera.height));
    }
    frames.push_back({c, *view});
  }
  return checkAndReport(rig, rigName, frames, opts, io);
}

}  // namespace

void addCheckCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<CheckOptions>();
  auto* cmd = app.add_subcommand(
      "check", "Health check: do the projectors' depths agree where they overlap? (one frame)");
  auto* rig = cmd->add_option("--rig", opts->rig, "Rig description (stripemux-rig/1 JSON)");
  auto* images =
      cmd->add_option("--images", opts->images,
                      "Folder with one frame's camera images, all projectors lit: <camera id>.png");
  auto* device = cmd->add_option(
      "--device", opts->device,
      "HOST[:PORT] of a device: one raw capture with every projector lit, checked with its rig");
  device->check(deviceAddressValidator())->excludes(rig)->excludes(images);
  cmd->add_option("--report", opts->report, "Folder for check.json and check.txt");
  cmd->add_flag("--json", opts->json, "Print the report as JSON (stripemux-check/1)");
  cmd->callback([opts, device, rig, images, &io, &exitCode] {
    if (device->count() > 0) {
      exitCode = runDeviceCheck(*opts, io);
    } else if (rig->count() == 0 || images->count() == 0) {
      exitCode = checkFailed(io, kExitUsage, "give --rig and --images, or --device");
    } else {
      exitCode = runCheck(*opts, io);
    }
  });
}

}  // namespace smx::host
