// stripemux eval [--out DIR] [--only SECTION,...] [--scene NAME ...] [--seed N]
//                [--supersampling N] [--cases N] [--no-projector-distortion]
// The evaluation suite: the named scenes rendered by the simulator, decoded by the firmware's
// pipeline and scored against the truth; writes DIR/results.md and DIR/results/*.png
// (docs/results.md is this command's output with the defaults); `--only health` writes
// DIR/health.md instead (docs/health.md), `--only calibration` DIR/calibration-results.md.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "calibration_eval.hpp"
#include "calibration_spread.hpp"
#include "commands.hpp"
#include "eval_report.hpp"
#include "output_folder.hpp"
#include "smx/eval/suite.hpp"
#include "smx/health/health_eval.hpp"
#include "smx/scan_eval/scan_markdown.hpp"
#include "smx/sim/named_scenes.hpp"
#include "smx/sim/scene.hpp"

namespace smx::host {
namespace {

struct EvalOptions {
  std::filesystem::path out = "docs";
  std::vector<std::string> only;
  std::vector<std::string> scenes;
  std::uint64_t seed = 1;
  int supersampling = 0;
  int cases = 60;
  bool noProjectorDistortion = false;
};

std::string commandLine(const EvalOptions& o) {
  std::string c = "stripemux eval";
  if (o.out != "docs") {
    c += " --out " + o.out.string();
  }
  for (std::size_t i = 0; i < o.only.size(); ++i) {
    c += (i == 0 ? " --only " : ",") + o.only[i];
  }
  for (const auto& s : o.scenes) {
    c += " --scene " + s;
  }
  if (o.seed != 1) {
    c += " --seed " + std::to_string(o.seed);
  }
  if (o.supersampling != 0) {
    c += " --supersampling " + std::to_string(o.supersampling);
  }
  if (o.cases != 60) {
    c += " --cases " + std::to_string(o.cases);
  }
  if (o.noProjectorDistortion) {
    c += " --no-projector-distortion";
  }
  return c;
}

// `--only health`: the health check's figures, DIR/health.md (health_eval.hpp).
int runHealthEval(const EvalOptions& o, const CliStreams& io) {
  health::HealthEvalOptions options;
  options.scenes = o.scenes;
  options.seed = o.seed;
  options.supersampling = o.supersampling;
  options.progress = [&io](const std::string& line) { io.out << line << '\n' << std::flush; };
  try {
    const auto cases = health::runHealthEval(options);
    auto out = OutputFolder::create(o.out);
    if (!out) {
      io.err << "stripemux eval: " << out.error() << '\n';
      return kExitDeviceOrIo;
    }
    if (auto ok = out->writeText("health.md", health::healthMarkdown(cases, commandLine(o)));
        !ok || !out->commit()) {
      io.err << "stripemux eval: cannot write " << (o.out / "health.md").string() << '\n';
      return kExitDeviceOrIo;
    }
  } catch (const std::exception& e) {
    io.err << "stripemux eval: " << e.what() << '\n';
    return kExitBadInput;
  }
  io.out << "wrote " << (o.out / "health.md").string() << '\n';
  return kExitOk;
}

// `--only calibration`: calibration on simulated captures against the real rig,
// DIR/calibration-results.md (calibration_eval.hpp). The captures stay in the system's temporary
// folder, stripemux-calibration-eval/, for inspection.
int runCalibrationEval(const EvalOptions& o, const CliStreams& io) {
  CalibrationEvalOptions options;
  options.scenes = o.scenes;
  options.seed = o.seed;
  options.work = std::filesystem::temp_directory_path() / "stripemux-calibration-eval";
  options.progress = [&io](const std::string& line) { io.out << line << '\n' << std::flush; };
  try {
    const auto cases = runCalibrationEval(options);
    SpreadOptions spread;
    spread.seed = o.seed;
    spread.work = options.work;
    spread.progress = options.progress;
    const auto runs = runCalibrationSpread(spread);
    auto out = OutputFolder::create(o.out);
    if (!out) {
      io.err << "stripemux eval: " << out.error() << '\n';
      return kExitDeviceOrIo;
    }
    if (auto ok =
            out->writeText("calibration-results.md", calibrationMarkdown(cases, commandLine(o)) +
                                                         spreadMarkdown(spread, runs));
        !ok || !out->commit()) {
      io.err << "stripemux eval: cannot write " << (o.out / "calibration-results.md").string()
             << '\n';
      return kExitDeviceOrIo;
    }
  } catch (const std::exception& e) {
    io.err << "stripemux eval: " << e.what() << '\n';
    return kExitBadInput;
  }
  io.out << "wrote " << (o.out / "calibration-results.md").string() << '\n';
  return kExitOk;
}

// `--only scan`: scans of the simulator's scenes against their true surfaces,
// DIR/scan-results.md (scan_eval).
int runScanEval(const EvalOptions& o, const CliStreams& io) {
  scan_eval::TurntableEvalOptions turntable;
  turntable.seed = o.seed;
  turntable.supersampling = o.supersampling;
  turntable.progress = [&io](const std::string& line) { io.out << line << '\n' << std::flush; };
  try {
    const auto result = scan_eval::runTurntableEval(turntable);
    scan_eval::HandheldEvalOptions handheld;
    handheld.seed = o.seed;
    handheld.supersampling = o.supersampling;
    handheld.progress = turntable.progress;
    const auto carried = scan_eval::runHandheldEval(handheld);
    auto out = OutputFolder::create(o.out);
    if (!out) {
      io.err << "stripemux eval: " << out.error() << '\n';
      return kExitDeviceOrIo;
    }
    if (auto ok = out->writeText("scan-results.md",
                                 scan_eval::scanResultsMarkdown(result, carried, commandLine(o)));
        !ok || !out->commit()) {
      io.err << "stripemux eval: cannot write " << (o.out / "scan-results.md").string() << '\n';
      return kExitDeviceOrIo;
    }
  } catch (const std::exception& e) {
    io.err << "stripemux eval: " << e.what() << '\n';
    return kExitBadInput;
  }
  io.out << "wrote " << (o.out / "scan-results.md").string() << '\n';
  return kExitOk;
}

int runEval(const EvalOptions& o, const CliStreams& io) {
  if (o.only.size() == 1 && o.only.front() == "health") {
    return runHealthEval(o, io);
  }
  if (o.only.size() == 1 && o.only.front() == "calibration") {
    return runCalibrationEval(o, io);
  }
  if (o.only.size() == 1 && o.only.front() == "scan") {
    return runScanEval(o, io);
  }
  eval::SuiteOptions suite;
  suite.seed = o.seed;
  suite.supersampling = o.supersampling;
  suite.realismCases = o.cases;
  suite.realism.projectorDistortion = !o.noProjectorDistortion;
  if (!o.only.empty()) {
    suite.sections.clear();
    for (const auto& name : o.only) {
      bool found = false;
      for (const auto s : eval::allSections()) {
        if (name == eval::sectionName(s)) {
          suite.sections.push_back(s);
          found = true;
        }
      }
      if (!found) {
        io.err << "stripemux eval: unknown section '" << name
               << "' (sections: scenes, flat, table2, baselines, sweeps, realism; or health, "
                  "calibration or scan "
               << "alone)\n";
        return kExitUsage;
      }
    }
  }
  const auto named = sim::namedScenes();
  for (const auto& scene : o.scenes) {
    if (std::ranges::find(named, scene) == named.end()) {
      io.err << "stripemux eval: unknown scene '" << scene << "' (named scenes:";
      for (const auto& n : named) {
        io.err << ' ' << n;
      }
      io.err << ")\n";
      return kExitUsage;
    }
  }
  suite.scenes = o.scenes;
  suite.progress = [&io](const std::string& line) { io.out << line << '\n' << std::flush; };
  eval::Report report;
  try {
    report = eval::runSuite(suite);
  } catch (const std::exception& e) {
    io.err << "stripemux eval: " << e.what() << '\n';
    return kExitBadInput;
  }
  if (auto ok = writeEvalReport(o.out, report, commandLine(o)); !ok) {
    io.err << "stripemux eval: " << ok.error() << '\n';
    return kExitDeviceOrIo;
  }
  io.out << "wrote " << (o.out / "results.md").string() << " and " << (o.out / "results").string()
         << "/ in " << std::lround(report.seconds) << " s\n";
  return kExitOk;
}

}  // namespace

void addEvalCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto options = std::make_shared<EvalOptions>();
  auto* cmd = app.add_subcommand(
      "eval",
      "Render the scene suite, decode it and score it against the truth: results.md + plots");
  cmd->add_option("--out", options->out, "Folder for results.md and results/ (default docs)");
  cmd->add_option(
         "--only", options->only,
         "Sections to run: scenes, flat, table2, baselines, sweeps, realism (default all); "
         "or health, calibration or scan alone (writes health.md, calibration-results.md, "
         "scan-results.md)")
      ->delimiter(',');
  cmd->add_option("--scene", options->scenes,
                  "Only the suite's runs of these named scenes (repeatable)");
  cmd->add_option("--seed", options->seed, "Noise seed of the renders (default 1)");
  cmd->add_option("--supersampling", options->supersampling,
                  "Samples per pixel side of every render (default: the scenes' own, 2)")
      ->check(CLI::Range(1, sim::kMaxSceneSupersampling));
  cmd->add_option("--cases", options->cases, "Generated scenes of the realism section (default 60)")
      ->check(CLI::Range(1, 10000));
  cmd->add_flag("--no-projector-distortion", options->noProjectorDistortion,
                "Realism section: projectors without lens distortion");
  cmd->callback([options, &io, &exitCode] { exitCode = runEval(*options, io); });
}

}  // namespace smx::host
