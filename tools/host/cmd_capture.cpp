// `stripemux capture`: raw camera frames from a device with chosen projectors lit, or a guided
// calibration capture set (docs/cli.md, docs/protocol.md "Raw capture").
#include <chrono>
#include <filesystem>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "calib_capture.hpp"
#include "commands.hpp"
#include "device_client.hpp"
#include "device_option.hpp"
#include "output_files.hpp"
#include "smx/net/tcp_client.hpp"
#include "smx/protocol/wire.hpp"
#include "terminal_text.hpp"

namespace smx::host {

namespace {

namespace fs = std::filesystem;

constexpr auto kConnectTimeout = std::chrono::milliseconds(3000);

struct CaptureOptions {
  std::string device;
  std::string projectors = "none";
  std::string sets;
  fs::path out;
  double timeoutS = 10;
  bool guided = false;
  int poses = 12;
  std::string target;  // COLSxROWS inner corners
  double squareM = 0;
};

// One capture: which projectors are lit and the file name prefix of its images.
struct LitSet {
  std::uint32_t mask = 0;
  std::string prefix;  // "" → <cam>.png, "proj0." → proj0.<cam>.png
};

std::expected<int, std::string> projectorIndex(const algo::Rig& rig, const std::string& id,
                                               const char* option) {
  for (std::size_t i = 0; i < rig.projectors.size(); ++i) {
    if (rig.projectors[i].id == id) {
      return static_cast<int>(i);
    }
  }
  std::string known;
  for (const auto& projector : rig.projectors) {
    known += (known.empty() ? "" : ", ") + projector.id;
  }
  return std::unexpected(std::string(option) + ": the device has no projector \"" + printable(id) +
                         "\" (it has " + known + ")");
}

std::vector<std::string> splitCommas(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  for (std::string part; std::getline(ss, part, ',');) {
    parts.push_back(part);
  }
  return parts;
}

// --projectors none|all|ID,ID…: one capture with those lit, files <cam>.png.
std::expected<LitSet, std::string> parseProjectors(const std::string& spec, const algo::Rig& rig) {
  if (spec == "none") {
    return LitSet{};
  }
  if (spec == "all") {
    return LitSet{.mask = (1U << rig.projectors.size()) - 1U, .prefix = ""};
  }
  LitSet set;
  for (const auto& id : splitCommas(spec)) {
    const auto index = projectorIndex(rig, id, "--projectors");
    if (!index) {
      return std::unexpected(index.error());
    }
    set.mask |= 1U << static_cast<unsigned>(*index);
  }
  return set;
}

// --sets none,ID,…: one capture per entry, named as a calibration pose's files.
std::expected<std::vector<LitSet>, std::string> parseSets(const std::string& spec,
                                                          const algo::Rig& rig) {
  std::vector<LitSet> sets;
  std::set<std::string> seen;
  for (const auto& entry : splitCommas(spec)) {
    if (!seen.insert(entry).second) {
      return std::unexpected("--sets: \"" + printable(entry) + "\" is given twice");
    }
    if (entry == "none") {
      sets.push_back({});
      continue;
    }
    const auto index = projectorIndex(rig, entry, "--sets");
    if (!index) {
      return std::unexpected(index.error());
    }
    sets.push_back({.mask = 1U << static_cast<unsigned>(*index), .prefix = entry + "."});
  }
  if (sets.empty()) {
    return std::unexpected("--sets: give none and/or projector ids, e.g. none,proj0,proj1");
  }
  return sets;
}

std::expected<CaptureGuideOptions, std::string> guideOptions(const CaptureOptions& opts) {
  CaptureGuideOptions guide;
  guide.poses = opts.poses;
  guide.squareM = opts.squareM;
  guide.captureTimeout = secondsOption(opts.timeoutS);
  if (!opts.target.empty()) {
    const auto x = opts.target.find('x');
    try {
      std::size_t used = 0;
      guide.cols = std::stoi(opts.target.substr(0, x), &used);
      const bool colsWhole = used == x;
      guide.rows = std::stoi(opts.target.substr(x + 1), &used);
      if (x == std::string::npos || !colsWhole || used != opts.target.size() - x - 1) {
        throw std::invalid_argument("COLSxROWS");
      }
    } catch (const std::exception&) {
      return std::unexpected("--target: expected COLSxROWS inner corners, e.g. 9x6, got \"" +
                             printable(opts.target) + "\"");
    }
  }
  return guide;
}

int runCapture(const CaptureOptions& opts, const CliStreams& io) {
  const auto fail = [&](int code, const std::string& message) {
    io.err << "stripemux capture: " << printable(message) << "\n";
    return code;
  };
  // What can be checked without the device is, before connecting.
  const auto guide = guideOptions(opts);
  if (!guide) {
    return fail(kExitUsage, guide.error());
  }
  auto client = DeviceClient::connect(opts.device, kConnectTimeout);
  if (!client) {
    return fail(kExitDeviceOrIo, client.error());
  }
  const algo::Rig& rig = client->info().rig;
  const auto timeout = secondsOption(opts.timeoutS);
  if (opts.guided) {
    const auto summary = captureCalibrationSet(*client, rig, *guide, opts.out, io);
    if (!summary) {
      return fail(kExitDeviceOrIo, summary.error());
    }
    return kExitOk;
  }
  std::vector<LitSet> sets;
  if (!opts.sets.empty()) {
    auto parsed = parseSets(opts.sets, rig);
    if (!parsed) {
      return fail(kExitUsage, parsed.error());
    }
    sets = std::move(*parsed);
  } else {
    auto parsed = parseProjectors(opts.projectors, rig);
    if (!parsed) {
      return fail(kExitUsage, parsed.error());
    }
    sets.push_back(*parsed);
  }
  auto out = OutputFolder::create(opts.out);
  if (!out) {
    return fail(kExitDeviceOrIo, out.error());
  }
  std::ostringstream report;
  for (const LitSet& set : sets) {
    auto capture = client->captureRaw(set.mask, timeout);
    if (!capture) {
      return fail(kExitDeviceOrIo, client->info().address + ": " + capture.error());
    }
    for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
      // Ids passed the rig's id rules; the folder checks the name again.
      const std::string name = set.prefix + rig.cameras[c].id + ".png";
      const auto image =
          *algo::ConstRgbView::packed(capture->images[c], capture->width, capture->height);
      if (auto written = writePngRgb8(*out, name, image); !written) {
        return fail(kExitDeviceOrIo, written.error());
      }
      report << "wrote " << out->pathOf(name).string() << "  (" << capture->width << "x"
             << capture->height << ", raw capture " << capture->capture << ")\n";
    }
  }
  if (auto committed = out->commit(); !committed) {
    return fail(kExitDeviceOrIo, committed.error());
  }
  io.out << report.str();
  return kExitOk;
}

}  // namespace

void addCaptureCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<CaptureOptions>();
  auto* cmd = app.add_subcommand(
      "capture", "Raw camera frames from a device with chosen projectors lit (PNG per camera)");
  cmd->add_option("--device", opts->device, "HOST[:PORT] of the device (default port 5555)")
      ->required()
      ->check(deviceAddressValidator());
  cmd->add_option("--out", opts->out, "Output directory")->required();
  auto* projectors = cmd->add_option(
      "--projectors", opts->projectors,
      "Projectors lit: none (default), all, or a comma-separated id list; writes <cam>.png");
  auto* sets = cmd->add_option("--sets", opts->sets,
                               "One capture per entry, none or a projector id, e.g. "
                               "none,proj0,proj1; writes <cam>.png and <proj>.<cam>.png");
  auto* guided = cmd->add_flag(
      "--guided", opts->guided,
      "Guided calibration capture: poses of a checkerboard into <out>/poseNN (docs/cli.md)");
  cmd->add_option("--poses", opts->poses, "With --guided: poses to capture (default 12)")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--target", opts->target,
                  "With --guided: the checkerboard's inner corners COLSxROWS, e.g. 9x6 (else "
                  "<out>/target.json)");
  cmd->add_option("--square", opts->squareM, "With --guided: the checkerboard's square, metres")
      ->check(CLI::Range(1e-4, 1.0));
  cmd->add_option("--timeout", opts->timeoutS, "Seconds to wait for each raw capture (default 10)")
      ->check(CLI::Range(0.1, 600.0));
  projectors->excludes(sets);
  guided->excludes(projectors)->excludes(sets);
  cmd->callback([opts, &io, &exitCode] { exitCode = runCapture(*opts, io); });
}

}  // namespace smx::host
