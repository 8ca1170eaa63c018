// stripemux scan --device HOST[:PORT] --turntable [--views N] --out DIR [fuse options]
// stripemux scan --device HOST[:PORT] --handheld [--frames N] --out DIR [fuse options]
// A whole object in one model (docs/scanning.md). Turntable: the device turns its table through N
// views and the host keeps each view's range images and colour in DIR/views as they arrive.
// Hand-held: every capture is tracked against the model so far as it arrives, until Ctrl-C or N
// captures; the well-tracked ones go to DIR/views with their poses. Then both are fused and
// meshed as `stripemux fuse DIR` does.
#include <atomic>
#include <chrono>
#include <csignal>
#include <memory>
#include <string>

#include "commands.hpp"
#include "device_client.hpp"
#include "device_option.hpp"
#include "fuse_runner.hpp"
#include "live_view.hpp"
#include "scan_handheld.hpp"
#include "scan_runner.hpp"
#include "scan_turntable.hpp"
#include "scan_views_writer.hpp"
#include "smx/scan/fuse.hpp"
#include "smx/scan/table_crop.hpp"
#include "smx/text/printf_text.hpp"
#include "terminal_text.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

int scanFailed(const CliStreams& io, int code, const std::string& message) {
  io.err << "stripemux scan: " << printable(message) << "\n";
  return code;
}

// "[#####·····] 5/24 views, 75.0°, 183412 points"
std::string progressLine(const TurntableStep& step) {
  constexpr int kWidth = 24;
  const int filled = (step.view + 1) * kWidth / step.views;
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.append(static_cast<std::size_t>(kWidth - filled), '.');
  return "[" + bar +
         text::printfText("] %d/%d views, table at %.1f°, %zu points", step.view + 1, step.views,
                          step.angleDeg, step.points);
}

// Why a scan that needs a table cannot have one, and what to do instead.
std::string noTurntable(const std::string& why) {
  return why + ": scan the object by hand (--handheld) or on a device with a turntable";
}

constexpr double kLiveModelVoxelM = 0.002;

// A view's points in the rig's frame, with colour when the view has it (no normals: the page
// draws points only).
scan::Cloud viewPoints(const DeviceInfo& info, const scan::RangeView& view) {
  scan::Cloud cloud;
  for (std::size_t c = 0; c < view.cameras.size() && c < info.rig.cameras.size(); ++c) {
    scan::append(cloud, scan::cameraPoints(info.rig.cameras[c], view.cameras[c], view.depthUnitM));
  }
  return scan::downsampled(cloud, kLiveModelVoxelM);
}

nlohmann::json scanStatus(std::string_view mode, std::string_view state, const fs::path& out,
                          const view::SidesSeen& sides, const scan::Cloud& model) {
  return {{"mode", mode},
          {"state", state},
          {"out", out.string()},
          {"coverage_pct", sides.percent()},
          {"model_points", model.size()}};
}

// Fuses and meshes the scan's folder; the page says so while it runs and how it ended.
int fuseForPage(const FuseFolderOptions& fuse, const CliStreams& io, LiveView* live,
                nlohmann::json status) {
  if (live != nullptr) {
    live->setScan(status);
    live->refresh();
  }
  const int code = runFuseFolder(fuse, io, "stripemux scan");
  if (live != nullptr) {
    status["state"] = code == kExitOk ? "done" : "failed";
    live->setScan(status);
    live->setMessage(code == kExitOk ? "model written to " + fuse.out
                                     : "the scan could not be fused: see the terminal");
    live->refresh();
  }
  return code;
}

int runTurntableScan(const ScanOptions& opts, const CliStreams& io, LiveView* live) {
  auto client = DeviceClient::connect(opts.device, kDeviceConnectTimeout);
  if (!client) {
    return scanFailed(io, kExitDeviceOrIo, client.error());
  }
  const DeviceInfo& info = client->info();
  // A device without a table is told apart from a table without a calibrated axis: the advice
  // differs.
  const TurntableCaptureOptions capture{
      .views = opts.views, .colour = !opts.noColour, .frameTimeout = secondsOption(opts.timeoutS)};
  auto table = client->turntableStatus(capture.frameTimeout);
  if (!table && !table.error().absent) {
    return scanFailed(io, kExitDeviceOrIo, table.error().message);
  }
  if (!table || !table->present) {
    return scanFailed(io, kExitBadInput,
                      noTurntable(table ? "the device has no turntable" : table.error().message));
  }
  if (!info.rig.turntable) {
    return scanFailed(io, kExitBadInput,
                      "the device's rig has no turntable axis: calibrate it (stripemux calibrate "
                      "--device " +
                          printable(opts.device) +
                          " --turntable --out RIG.json) and install the rig (stripemux config set "
                          "rig=RIG.json)");
  }
  auto writer = ViewsWriter::create(opts.out, info.rig, info.rigJson, scan::ScanMode::kTurntable);
  if (!writer) {
    return scanFailed(io, kExitDeviceOrIo, writer.error());
  }
  io.out << "connected to " << printable(info.address) << ": " << printable(info.board) << ", "
         << info.cameras << " cameras; " << opts.views << " views into "
         << (opts.out / "views").string() << "\n";
  const auto start = std::chrono::steady_clock::now();
  const scan::TurntableAxis axis{
      Eigen::Vector3d(info.rig.turntable->axis[0], info.rig.turntable->axis[1],
                      info.rig.turntable->axis[2])
          .normalized(),
      Eigen::Vector3d(info.rig.turntable->point[0], info.rig.turntable->point[1],
                      info.rig.turntable->point[2])};
  scan::Cloud model;  // the live view's: each view placed by the table's angle
  view::SidesSeen sides;
  if (live != nullptr) {
    live->setDevice(info, {});
    live->setScan(scanStatus("turntable", "turning", opts.out, sides, model));
    live->refresh();
  }
  auto views = captureTurntableViews(
      *client, capture,
      [&](const scan::RangeView& view,
          const TurntableStep& step) -> std::expected<void, std::string> {
        if (auto ok = writer->add(view); !ok) {
          return ok;
        }
        io.out << progressLine(step) << "\n" << std::flush;
        if (live != nullptr) {
          live->view(view);
          // As fusion does: only what stands on the table turns with it.
          scan::RangeView onTable = view;
          scan::keepOnTable(onTable, info.rig, axis, opts.fuse.tableRadiusMm * 1e-3);
          scan::append(model, scan::transformed(viewPoints(info, onTable),
                                                scan::turntablePose(axis, step.angleDeg)));
          model = scan::downsampled(model, kLiveModelVoxelM);
          sides.add(step.angleDeg);
          live->model(model);
          auto status = scanStatus("turntable", "turning", opts.out, sides, model);
          status["views"] = step.views;
          status["views_done"] = step.view + 1;
          live->setScan(status);
          live->refresh();
        }
        return {};
      });
  if (!views) {
    const bool absent = views.error().starts_with("the device has no turntable");
    return scanFailed(io, absent ? kExitBadInput : kExitDeviceOrIo, views.error());
  }
  client->close();
  if (auto ok = writer->finish({}); !ok) {
    return scanFailed(io, kExitDeviceOrIo, ok.error());
  }
  const double captureS =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  io.out << "captured " << views->size() << " views in " << std::lround(captureS) << " s; fusing\n";
  FuseFolderOptions fuse = opts.fuse;
  fuse.dir = opts.out.string();
  fuse.out = opts.out.string();
  return fuseForPage(fuse, io, live, scanStatus("turntable", "fusing", opts.out, sides, model));
}

// Ctrl-C ends a hand-held scan the way --frames does: the stream stops and the model is made.
std::atomic<bool> interrupted{false};
extern "C" void onInterrupt(int /*signal*/) {
  interrupted.store(true);
}

const char* stateName(const scan::TrackResult& r) {
  if (r.state == scan::TrackingState::kLost) {
    return "LOST";
  }
  if (r.state == scan::TrackingState::kRelocalised) {
    return "relocalised";
  }
  return r.quality.good ? "tracking" : "weak";
}

// The sides of the model the fused captures saw: azimuths of the rig's centre about the model's
// centroid, in the plane across the first capture's vertical (its y axis).
view::SidesSeen sidesAround(const scan::Cloud& model, const std::vector<Eigen::Vector3d>& centres) {
  view::SidesSeen sides;
  if (model.empty()) {
    return sides;
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : model.points) {
    centroid += p;
  }
  centroid /= static_cast<double>(model.size());
  for (const auto& c : centres) {
    const Eigen::Vector3d d = c - centroid;
    sides.add(std::atan2(d.x(), -d.z()) * 180.0 / std::numbers::pi);
  }
  return sides;
}

int runHandheldScan(const ScanOptions& opts, const CliStreams& io, LiveView* live) {
  auto client = DeviceClient::connect(opts.device, kDeviceConnectTimeout);
  if (!client) {
    return scanFailed(io, kExitDeviceOrIo, client.error());
  }
  const DeviceInfo& info = client->info();
  auto tracker = scan::Tracker::create(info.rig);
  if (!tracker) {
    return scanFailed(io, kExitBadInput, tracker.error());
  }
  auto writer = ViewsWriter::create(opts.out, info.rig, info.rigJson, scan::ScanMode::kHandheld);
  if (!writer) {
    return scanFailed(io, kExitDeviceOrIo, writer.error());
  }
  io.out << "connected to " << printable(info.address) << ": " << printable(info.board) << ", "
         << info.cameras << " cameras at " << info.fps << " fps; move round the object, "
         << (opts.frames > 0 ? "stops after " + std::to_string(opts.frames) + " captures"
                             : std::string("Ctrl-C to stop"))
         << "\n";
  std::vector<std::optional<scan::Pose>> poses;
  auto lastLine = std::chrono::steady_clock::now();
  scan::TrackingState lastState = scan::TrackingState::kTracking;
  interrupted.store(false);
  const auto previous = std::signal(SIGINT, onInterrupt);
  const HandheldCaptureOptions capture{.frames = opts.frames,
                                       .frameTimeout = secondsOption(opts.timeoutS)};
  int captures = 0;
  int fused = 0;
  std::vector<Eigen::Vector3d> fusedCentres;  // the rig's centre at each fused capture
  view::SidesSeen sides;
  scan::Cloud model;
  auto lastPage = std::chrono::steady_clock::now();
  if (live != nullptr) {
    live->setDevice(info, {.stopScan = true});
    live->setScan(scanStatus("handheld", "starting", opts.out, sides, model));
    live->refresh();
  }
  auto tally = trackHandheld(
      *client, *tracker, capture, interrupted,
      [&](const scan::RangeView& view,
          const scan::TrackResult& result) -> std::expected<void, std::string> {
        ++captures;
        if (result.fused) {
          ++fused;
          if (auto ok = writer->add(view); !ok) {
            return ok;
          }
          poses.emplace_back(result.pose);
          fusedCentres.emplace_back(result.pose.translation());
        }
        if (live != nullptr) {
          live->view(view);
          if (const auto now = std::chrono::steady_clock::now();
              now - lastPage >= std::chrono::seconds(1)) {
            lastPage = now;
            model = tracker->model();
            sides = sidesAround(model, fusedCentres);
            live->model(model);
            auto status = scanStatus("handheld", stateName(result), opts.out, sides, model);
            status["captures"] = captures;
            status["fused"] = fused;
            status["lost"] = captures - fused;
            status["quality"] = result.quality.score;
            live->setScan(status);
            live->refresh();
          }
          for (const view::Control& control : live->takeControls()) {
            if (control.action == "stop-scan") {
              interrupted.store(true);
            }
          }
        }
        // A line twice a second, and at once when tracking is lost or found again.
        const auto now = std::chrono::steady_clock::now();
        if (now - lastLine >= std::chrono::milliseconds(500) || result.state != lastState) {
          lastLine = now;
          io.out << text::printfText(
                        "  capture %d: %-11s fitness %.2f, %.2f mm, score %.2f; %d fused, %zu "
                        "keyframes",
                        captures, stateName(result), result.quality.fitness,
                        result.quality.inlierRmseMm, result.quality.score, fused,
                        tracker->keyframes())
                 << (result.reason.empty() ? "" : " (" + result.reason + ")") << "\n"
                 << std::flush;
        }
        lastState = result.state;
        return {};
      });
  std::signal(SIGINT, previous);
  if (!tally) {
    return scanFailed(io, kExitDeviceOrIo, tally.error());
  }
  client->close();
  if (auto ok = writer->finish(poses); !ok) {
    return scanFailed(io, kExitDeviceOrIo, ok.error());
  }
  const double trackMs = tally->captures > 0 ? tally->trackMsTotal / tally->captures : 0.0;
  io.out << text::printfText(
      "%d captures: %d fused, %d lost, %d relocalised; tracking %.1f ms a capture; the device "
      "dropped %llu frames the host was too slow for\n",
      tally->captures, tally->fused, tally->lost, tally->relocalised, trackMs,
      static_cast<unsigned long long>(tally->device.framesDropped));
  if (tally->fused < 2) {
    return scanFailed(
        io, kExitBadInput,
        "only " + std::to_string(tally->fused) +
            " captures tracked well enough to fuse: scan again, moving slowly over the "
            "object and keeping it in view");
  }
  FuseFolderOptions fuse = opts.fuse;
  fuse.dir = opts.out.string();
  fuse.out = opts.out.string();
  fuse.tracking = TrackingSummary{.captures = tally->captures,
                                  .fused = tally->fused,
                                  .lost = tally->lost,
                                  .relocalised = tally->relocalised,
                                  .trackMsMean = trackMs,
                                  .deviceFramesDropped = tally->device.framesDropped};
  return fuseForPage(fuse, io, live, scanStatus("handheld", "fusing", opts.out, sides, model));
}

}  // namespace

int runScan(const ScanOptions& opts, const CliStreams& io, LiveView* live) {
  return opts.turntable ? runTurntableScan(opts, io, live) : runHandheldScan(opts, io, live);
}

void addScanCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<ScanOptions>();
  auto* cmd = app.add_subcommand("scan",
                                 "Scan a whole object into one model: turntable views or a "
                                 "hand-held stream, fused and meshed");
  cmd->add_option("--device", opts->device, "HOST[:PORT] of the device")
      ->required()
      ->check(deviceAddressValidator());
  cmd->add_option("--out", opts->out, "Folder for the views and the model")->required();
  auto* turntable =
      cmd->add_flag("--turntable", opts->turntable, "Turn the device's table through the views");
  cmd->add_option("--views", opts->views, "Views over one turn of the table (default 24)")
      ->check(CLI::Range(2, 360))
      ->needs(turntable);
  auto* handheld = cmd->add_flag("--handheld", opts->handheld,
                                 "Track and fuse the stream while the scanner is moved by hand");
  handheld->excludes(turntable);
  cmd->add_option("--frames", opts->frames,
                  "With --handheld: stop after N captures (default: "
                  "Ctrl-C)")
      ->check(CLI::Range(1, 100000))
      ->needs(handheld);
  cmd->add_flag("--no-colour", opts->noColour,
                "Skip the projector-off frame of each view (the model is grey)");
  cmd->add_option("--timeout", opts->timeoutS,
                  "Seconds to wait for each frame and status answer (default 10)")
      ->check(CLI::Range(0.1, 3600.0));
  addFuseOptions(*cmd, opts->fuse);
  auto liveView = std::make_shared<bool>(false);
  auto page = std::make_shared<view::ServerOptions>();
  auto* viewFlag =
      cmd->add_flag("--view", *liveView, "Show the scan live in a browser (stripemux view's page)");
  addPageOptions(*cmd, *page, "--view-", viewFlag);
  cmd->callback([opts, liveView, page, &io, &exitCode] {
    if (!opts->turntable && !opts->handheld) {
      exitCode = scanFailed(io, kExitUsage, "give --turntable or --handheld");
      return;
    }
    if (!*liveView) {
      exitCode = runScan(*opts, io, nullptr);
      return;
    }
    auto live = LiveView::start(*page);
    if (!live) {
      exitCode = scanFailed(io, kExitDeviceOrIo, live.error());
      return;
    }
    io.out << "live view: " << (*live)->url() << "\n" << std::flush;
    exitCode = runScan(*opts, io, live->get());
  });
}

}  // namespace smx::host
