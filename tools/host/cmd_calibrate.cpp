// stripemux calibrate --rig NOMINAL.json --captures DIR --out RIG.json [--report DIR]
// A rig's cameras and projectors from captures of a printed target (docs/calibration.md). The
// rig file is written only when the solve succeeds, and then whole or not at all.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "commands.hpp"
#include "output_folder.hpp"
#include "smx/calib/calibrate.hpp"
#include "smx/calib/report.hpp"
#include "smx/config/rig_json.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

struct CalibrateOptions {
  fs::path rig;
  fs::path captures;
  fs::path out;
  std::optional<fs::path> report;
};

int fail(const CliStreams& io, int code, const std::string& message) {
  io.err << "stripemux calibrate: " << message << "\n";
  return code;
}

int runCalibrate(const CalibrateOptions& opts, const CliStreams& io) {
  const auto nominal = config::loadRig(opts.rig);
  if (!nominal) {
    return fail(io, kExitBadInput, nominal.error().message());
  }
  const fs::path outFile = opts.out.filename();
  if (const auto problem = fileNameProblem(outFile.string())) {
    return fail(io, kExitUsage, "--out " + opts.out.string() + ": " + *problem);
  }
  // A failed solve leaves an earlier rig and report as they were.
  const std::string untouched = "; nothing written (" + opts.out.string() +
                                (opts.report ? ", " + opts.report->string() : "") + ")";
  auto calibration = calib::calibrate(*nominal, opts.captures);
  if (!calibration) {
    return fail(io, kExitBadInput, calibration.error() + untouched);
  }
  if (auto valid = config::validateRig(calibration->rig); !valid) {
    return fail(
        io, kExitBadInput,
        "the solve failed: the solved rig is not valid: " + valid.error().message() + untouched);
  }
  const std::string text = calib::reportText(*calibration);
  auto rigDir = OutputFolder::create(opts.out.has_parent_path() ? opts.out.parent_path() : ".");
  if (!rigDir) {
    return fail(io, kExitDeviceOrIo, rigDir.error());
  }
  if (auto ok = rigDir->writeText(outFile.string(), config::toJson(calibration->rig)); !ok) {
    return fail(io, kExitDeviceOrIo, ok.error());
  }
  std::optional<OutputFolder> reportDir;
  if (opts.report) {
    auto dir = OutputFolder::create(*opts.report);
    if (!dir) {
      return fail(io, kExitDeviceOrIo, dir.error());
    }
    reportDir.emplace(std::move(*dir));
    for (const auto& [name, body] :
         {std::pair<std::string, std::string>{"report.json",
                                              calib::reportJson(*calibration).dump(2) + "\n"},
          {"summary.txt", text}}) {
      if (auto ok = reportDir->writeText(name, body); !ok) {
        return fail(io, kExitDeviceOrIo, ok.error());
      }
    }
  }
  if (auto ok = reportDir ? reportDir->commit() : std::expected<void, std::string>{}; !ok) {
    return fail(io, kExitDeviceOrIo, ok.error());
  }
  if (auto ok = rigDir->commit(); !ok) {
    return fail(io, kExitDeviceOrIo, ok.error());
  }
  io.out << text << "wrote " << opts.out.string() << "\n";
  return kExitOk;
}

}  // namespace

void addCalibrateCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<CalibrateOptions>();
  auto* cmd = app.add_subcommand(
      "calibrate", "A rig's cameras and projectors from captures of a printed target");
  cmd->add_option("--rig", opts->rig,
                  "The rig as designed (stripemux-rig/1): ids, sizes, "
                  "patterns and rough poses")
      ->required();
  cmd->add_option("--captures", opts->captures,
                  "Folder of target.json and pose00/, pose01/, … (docs/calibration.md)")
      ->required();
  cmd->add_option("--out", opts->out, "The calibrated rig.json to write")->required();
  cmd->add_option("--report", opts->report, "Folder for report.json and summary.txt");
  cmd->callback([opts, &io, &exitCode] { exitCode = runCalibrate(*opts, io); });
}

}  // namespace smx::host
