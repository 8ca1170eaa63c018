// stripemux calibrate --rig NOMINAL.json --captures DIR --out RIG.json [--report DIR]
// stripemux calibrate --device HOST[:PORT] --poses N --out RIG.json [--captures DIR] [--report DIR]
// stripemux calibrate --turntable --rig RIG.json --captures DIR --out RIG2.json
// stripemux calibrate --turntable --device HOST[:PORT] --out RIG2.json [--views N] [--span DEG]
// A rig's cameras and projectors, or its turntable's axis, from captures of a printed target
// (docs/calibration.md), taken beforehand or, with --device, by the guided capture first. The rig
// file is written only when the solve succeeds, and then whole or not at all.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <tuple>

#include "calib_capture.hpp"
#include "commands.hpp"
#include "device_client.hpp"
#include "device_option.hpp"
#include "output_folder.hpp"
#include "smx/calib/calibrate.hpp"
#include "smx/calib/report.hpp"
#include "smx/calib/table_captures.hpp"
#include "smx/config/rig_json.hpp"
#include "table_capture.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

struct CalibrateOptions {
  fs::path rig;
  fs::path captures;
  fs::path out;
  std::optional<fs::path> report;
  // The --device form: the guided capture into `captures` (default beside `out`) first.
  std::string device;
  int poses = 12;
  std::string target;  // COLSxROWS inner corners
  double squareM = 0;
  // The turntable's axis from captures of the target on the table, added to a calibrated rig;
  // with --device, `views` of them over `spanDeg`, the device turning its table.
  bool turntable = false;
  int views = 8;
  double spanDeg = 80.0;
};

int calibrationFailed(const CliStreams& io, int code, const std::string& message) {
  io.err << "stripemux calibrate: " << message << "\n";
  return code;
}

// The solve and the writing of the rig and the report, shared by both forms.
int solveAndWrite(const algo::Rig& nominal, const CalibrateOptions& opts, const CliStreams& io) {
  const fs::path outFile = opts.out.filename();
  if (const auto problem = fileNameProblem(outFile.string())) {
    return calibrationFailed(io, kExitUsage, "--out " + opts.out.string() + ": " + *problem);
  }
  // A failed solve leaves an earlier rig and report as they were.
  const std::string untouched = "; nothing written (" + opts.out.string() +
                                (opts.report ? ", " + opts.report->string() : "") + ")";
  auto calibration = calib::calibrate(nominal, opts.captures);
  if (!calibration) {
    return calibrationFailed(io, kExitBadInput, calibration.error() + untouched);
  }
  if (auto valid = config::validateRig(calibration->rig); !valid) {
    return calibrationFailed(
        io, kExitBadInput,
        "the solve failed: the solved rig is not valid: " + valid.error().message() + untouched);
  }
  const std::string text = calib::reportText(*calibration);
  auto rigDir = OutputFolder::create(opts.out.has_parent_path() ? opts.out.parent_path() : ".");
  if (!rigDir) {
    return calibrationFailed(io, kExitDeviceOrIo, rigDir.error());
  }
  if (auto ok = rigDir->writeText(outFile.string(), config::toJson(calibration->rig)); !ok) {
    return calibrationFailed(io, kExitDeviceOrIo, ok.error());
  }
  std::optional<OutputFolder> reportDir;
  if (opts.report) {
    auto dir = OutputFolder::create(*opts.report);
    if (!dir) {
      return calibrationFailed(io, kExitDeviceOrIo, dir.error());
    }
    reportDir.emplace(std::move(*dir));
    for (const auto& [name, body] :
         {std::pair<std::string, std::string>{"report.json",
                                              calib::reportJson(*calibration).dump(2) + "\n"},
          {"summary.txt", text}}) {
      if (auto ok = reportDir->writeText(name, body); !ok) {
        return calibrationFailed(io, kExitDeviceOrIo, ok.error());
      }
    }
  }
  if (auto ok = reportDir ? reportDir->commit() : std::expected<void, std::string>{}; !ok) {
    return calibrationFailed(io, kExitDeviceOrIo, ok.error());
  }
  if (auto ok = rigDir->commit(); !ok) {
    return calibrationFailed(io, kExitDeviceOrIo, ok.error());
  }
  io.out << text << "wrote " << opts.out.string() << "\n";
  return kExitOk;
}

int runCalibrate(const CalibrateOptions& opts, const CliStreams& io) {
  const auto nominal = config::loadRig(opts.rig);
  if (!nominal) {
    return calibrationFailed(io, kExitBadInput, nominal.error().message());
  }
  return solveAndWrite(*nominal, opts, io);
}

// --turntable: `rig` with the table's axis from the captures; its cameras must be calibrated.
int solveTableAndWrite(algo::Rig rig, const CalibrateOptions& opts, const CliStreams& io) {
  const fs::path outFile = opts.out.filename();
  const std::string untouched = "; nothing written (" + opts.out.string() + ")";
  auto table = calib::calibrateTable(rig, opts.captures);
  if (!table) {
    return calibrationFailed(io, kExitBadInput, table.error() + untouched);
  }
  const auto& axis = table->axis;
  rig.turntable =
      algo::TurntableAxis{.axis = {axis.direction.x(), axis.direction.y(), axis.direction.z()},
                          .point = {axis.point.x(), axis.point.y(), axis.point.z()}};
  auto rigDir = OutputFolder::create(opts.out.has_parent_path() ? opts.out.parent_path() : ".");
  if (!rigDir) {
    return calibrationFailed(io, kExitDeviceOrIo, rigDir.error());
  }
  if (auto ok = rigDir->writeText(outFile.string(), config::toJson(rig)); !ok) {
    return calibrationFailed(io, kExitDeviceOrIo, ok.error());
  }
  if (auto ok = rigDir->commit(); !ok) {
    return calibrationFailed(io, kExitDeviceOrIo, ok.error());
  }
  io.out << calib::tableReportText(*table) << "wrote " << opts.out.string() << "\n";
  return kExitOk;
}

int runTableCalibrate(const CalibrateOptions& opts, const CliStreams& io) {
  if (const auto problem = fileNameProblem(opts.out.filename().string())) {
    return calibrationFailed(io, kExitUsage, "--out " + opts.out.string() + ": " + *problem);
  }
  auto rig = config::loadRig(opts.rig);
  if (!rig) {
    return calibrationFailed(
        io, kExitBadInput, rig.error().message() + "; nothing written (" + opts.out.string() + ")");
  }
  return solveTableAndWrite(std::move(*rig), opts, io);
}

// RIG.json → RIG.captures beside it.
fs::path defaultCaptures(const fs::path& out) {
  return out.parent_path() / (out.stem().string() + ".captures");
}

// The target from --target and --square, or nothing given (0s); a malformed --target is the
// error.
std::expected<std::tuple<int, int, double>, std::string> givenTarget(const CalibrateOptions& opts) {
  if (opts.target.empty()) {
    return std::tuple{0, 0, opts.squareM};
  }
  const auto corners = parseInnerCorners(opts.target);
  if (!corners) {
    return std::unexpected(corners.error());
  }
  return std::tuple{corners->first, corners->second, opts.squareM};
}

// What the guided forms check before connecting: --out's name, a captures folder (default
// RIG.captures beside --out, set in opts) without an earlier session's `first` folder, and a
// target given or on file. The target's inner corners and square (0s: on file), or the exit code
// after the message.
std::expected<std::tuple<int, int, double>, int> checkBeforeCapture(CalibrateOptions& opts,
                                                                    const std::string& first,
                                                                    const CliStreams& io) {
  if (const auto problem = fileNameProblem(opts.out.filename().string())) {
    return std::unexpected(
        calibrationFailed(io, kExitUsage, "--out " + opts.out.string() + ": " + *problem));
  }
  const auto target = givenTarget(opts);
  if (!target) {
    return std::unexpected(calibrationFailed(io, kExitUsage, target.error()));
  }
  if (opts.captures.empty()) {
    opts.captures = defaultCaptures(opts.out);
  }
  // Captures of an earlier session beside new ones would be solved as one set.
  std::error_code ec;
  if (fs::exists(opts.captures / first, ec)) {
    return std::unexpected(calibrationFailed(io, kExitUsage,
                                             opts.captures.string() + " already holds captures (" +
                                                 first +
                                                 "/): give another --captures or remove them"));
  }
  const auto& [cols, rows, squareM] = *target;
  if ((cols == 0 || squareM == 0) && !fs::exists(opts.captures / "target.json", ec)) {
    return std::unexpected(
        calibrationFailed(io, kExitUsage,
                          "no target: give --target COLSxROWS and --square M, or write " +
                              (opts.captures / "target.json").string()));
  }
  return *target;
}

// --turntable --device: the device turns its table through the views, then the axis is solved
// with the device's rig.
int runDeviceTableCalibrate(CalibrateOptions opts, const CliStreams& io) {
  const auto target = checkBeforeCapture(opts, "view00", io);
  if (!target) {
    return target.error();
  }
  TableCaptureOptions capture;
  capture.views = opts.views;
  capture.spanDeg = opts.spanDeg;
  std::tie(capture.cols, capture.rows, capture.squareM) = *target;
  auto client = DeviceClient::connect(opts.device, kDeviceConnectTimeout);
  if (!client) {
    return calibrationFailed(io, kExitDeviceOrIo, client.error());
  }
  algo::Rig rig = client->info().rig;
  const auto captured = captureTableSet(*client, rig, capture, opts.captures, io);
  client->close();
  if (!captured) {
    const bool noTable = captured.error().starts_with("the device has no turntable");
    return calibrationFailed(io, noTable ? kExitBadInput : kExitDeviceOrIo,
                             captured.error() + "; nothing written (" + opts.out.string() + ")");
  }
  return solveTableAndWrite(std::move(rig), opts, io);
}

int runDeviceCalibrate(CalibrateOptions opts, const CliStreams& io) {
  // What can be checked without the device is, before connecting.
  const auto target = checkBeforeCapture(opts, "pose00", io);
  if (!target) {
    return target.error();
  }
  CaptureGuideOptions guide;
  guide.poses = opts.poses;
  std::tie(guide.cols, guide.rows, guide.squareM) = *target;
  auto client = DeviceClient::connect(opts.device, kDeviceConnectTimeout);
  if (!client) {
    return calibrationFailed(io, kExitDeviceOrIo, client.error());
  }
  const algo::Rig nominal = client->info().rig;
  const auto captured = captureCalibrationSet(*client, nominal, guide, opts.captures, io);
  client->close();
  if (!captured) {
    return calibrationFailed(io, kExitDeviceOrIo, captured.error());
  }
  return solveAndWrite(nominal, opts, io);
}

}  // namespace

void addCalibrateCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<CalibrateOptions>();
  auto* cmd = app.add_subcommand(
      "calibrate", "A rig's cameras and projectors from captures of a printed target");
  auto* rig = cmd->add_option("--rig", opts->rig,
                              "The rig as designed (stripemux-rig/1): ids, sizes, "
                              "patterns and rough poses");
  auto* captures =
      cmd->add_option("--captures", opts->captures,
                      "Folder of target.json and pose00/, pose01/, … (docs/calibration.md); "
                      "with --device, where the guided capture writes them (default RIG.captures "
                      "beside --out)");
  cmd->add_option("--out", opts->out, "The calibrated rig.json to write")->required();
  cmd->add_option("--report", opts->report, "Folder for report.json and summary.txt");
  auto* device = cmd->add_option(
      "--device", opts->device,
      "HOST[:PORT] of a device: capture the poses (with --turntable, the table's views) there, "
      "guided, then solve with its rig");
  device->check(deviceAddressValidator())->excludes(rig);
  auto* poses =
      cmd->add_option("--poses", opts->poses, "With --device: poses to capture (default 12)")
          ->check(CLI::Range(1, 100))
          ->needs(device);
  cmd->add_option("--target", opts->target,
                  "With --device: the checkerboard's inner corners COLSxROWS, e.g. 9x6 (else "
                  "<captures>/target.json)")
      ->needs(device);
  cmd->add_option("--square", opts->squareM, "With --device: the checkerboard's square, metres")
      ->check(CLI::Range(1e-4, 1.0))
      ->needs(device);
  auto* turntable =
      cmd->add_flag("--turntable", opts->turntable,
                    "Find the turntable's axis from --captures of the target leaning on the table "
                    "(see stripemux sim --table-calibration) and write --rig with it; with "
                    "--device, the device turns its table and the views are captured first")
          ->excludes(poses);
  cmd->add_option("--views", opts->views,
                  "With --device --turntable: table angles to capture (default 8)")
      ->check(CLI::Range(4, 72))
      ->needs(device)
      ->needs(turntable);
  cmd->add_option("--span", opts->spanDeg,
                  "With --device --turntable: degrees the views spread over, centred where the "
                  "table stands (default 80)")
      ->check(CLI::Range(30.0, 360.0))
      ->needs(device)
      ->needs(turntable);
  cmd->callback([opts, device, rig, captures, &io, &exitCode] {
    if (opts->turntable && device->count() > 0) {
      exitCode = runDeviceTableCalibrate(*opts, io);
    } else if (opts->turntable) {
      exitCode = rig->count() == 0 || captures->count() == 0
                     ? calibrationFailed(
                           io, kExitUsage,
                           "--turntable needs --rig (calibrated) and --captures, or --device")
                     : runTableCalibrate(*opts, io);
    } else if (device->count() > 0) {
      exitCode = runDeviceCalibrate(*opts, io);
    } else if (rig->count() == 0 || captures->count() == 0) {
      exitCode = calibrationFailed(
          io, kExitUsage,
          "give --rig and --captures (captures taken before), or --device (capture "
          "there first)");
    } else {
      exitCode = runCalibrate(*opts, io);
    }
  });
}

}  // namespace smx::host
