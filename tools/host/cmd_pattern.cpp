// stripemux pattern --rig rig.json --out DIR
// Writes each projector's pattern image, DIR/<projector-id>.png, as the projector must show it.
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "output_files.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::host {
namespace {

struct PatternOptions {
  std::filesystem::path rig;
  std::filesystem::path out;
};

int runPattern(const PatternOptions& opts, const CliStreams& io) {
  auto rig = config::loadRig(opts.rig);
  if (!rig) {
    io.err << "stripemux pattern: " << rig.error().message() << "\n";
    return kExitBadInput;
  }
  auto out = OutputFolder::create(opts.out);
  if (!out) {
    io.err << "stripemux pattern: " << out.error() << "\n";
    return kExitDeviceOrIo;
  }
  std::string report;
  for (const auto& projector : rig->projectors) {
    std::vector<algo::Rgb8> pixels(static_cast<std::size_t>(projector.width) *
                                   static_cast<std::size_t>(projector.height));
    const auto view = algo::RgbView::packed(pixels, projector.width, projector.height);
    if (!view) {
      io.err << "stripemux pattern: " << projector.id << ": " << view.error().message << "\n";
      return kExitBadInput;
    }
    if (const auto rendered = algo::renderPatternImage(projector, *view); !rendered) {
      io.err << "stripemux pattern: " << projector.id << ": " << rendered.error().message << "\n";
      return kExitBadInput;
    }
    const std::string name = projector.id + ".png";
    if (auto written = writePngRgb8(*out, name, *view); !written) {
      io.err << "stripemux pattern: " << written.error() << "\n";
      return kExitDeviceOrIo;
    }
    std::ostringstream line;
    line << "wrote " << out->pathOf(name).string() << "  (" << projector.width << "x"
         << projector.height << ", axis " << projector.pattern.angleDeg << " deg, "
         << projector.pattern.stripePx << " px stripes, " << algo::visibleStripes(projector)
         << " of " << algo::stripe::kStripes << " stripes fully visible)\n";
    report += line.str();
  }
  if (auto committed = out->commit(); !committed) {
    io.err << "stripemux pattern: " << committed.error() << "\n";
    return kExitDeviceOrIo;
  }
  io.out << report;
  return kExitOk;
}

}  // namespace

void addPatternCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<PatternOptions>();
  auto* cmd = app.add_subcommand("pattern", "Write each projector's stripe pattern image");
  cmd->add_option("--rig", opts->rig, "Rig description (stripemux-rig/1 JSON)")->required();
  cmd->add_option("--out", opts->out, "Output directory; writes <projector-id>.png")->required();
  cmd->callback([opts, &io, &exitCode] { exitCode = runPattern(*opts, io); });
}

}  // namespace smx::host
