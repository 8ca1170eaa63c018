// stripemux pattern --rig rig.json --out DIR
// Writes each projector's pattern image, DIR/<projector-id>.png, as the projector must show it.
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <system_error>
#include <vector>

#include "commands.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/protocol/rig_json.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::host {
namespace {

struct PatternOptions {
  std::filesystem::path rig;
  std::filesystem::path out;
};

// Stripes whose whole width lies inside the projector image.
int visibleStripes(const algo::Projector& p) {
  const double a = p.pattern.angleDeg * std::numbers::pi / 180.0;
  int visible = 0;
  for (int i = 0; i < algo::stripe::kStripes; ++i) {
    bool inside = true;
    for (const double edge : {static_cast<double>(i), i + 1.0}) {
      const double along =
          p.pattern.offsetPx + (edge - algo::stripe::kStripes / 2.0) * p.pattern.stripePx;
      const double u = (p.width - 1) / 2.0 + along * std::cos(a);
      const double v = (p.height - 1) / 2.0 + along * std::sin(a);
      inside = inside && u >= -0.5 && v >= -0.5 && u <= p.width - 0.5 && v <= p.height - 0.5;
    }
    visible += inside ? 1 : 0;
  }
  return visible;
}

int runPattern(const PatternOptions& opts, const CliStreams& io) {
  auto rig = protocol::loadRig(opts.rig);
  if (!rig) {
    io.err << "stripemux pattern: " << rig.error().message() << "\n";
    return kExitBadInput;
  }
  std::error_code ec;
  std::filesystem::create_directories(opts.out, ec);
  if (ec) {
    io.err << "stripemux pattern: cannot create output directory " << opts.out.string() << ": "
           << ec.message() << "\n";
    return kExitDeviceOrIo;
  }
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
    const auto file = opts.out / (projector.id + ".png");
    if (auto written = sim::writePngRgb8(file, *view); !written) {
      io.err << "stripemux pattern: " << written.error() << "\n";
      return kExitDeviceOrIo;
    }
    io.out << "wrote " << file.string() << "  (" << projector.width << "x" << projector.height
           << ", axis " << projector.pattern.angleDeg << " deg, " << projector.pattern.stripePx
           << " px stripes, " << visibleStripes(projector) << " of " << algo::stripe::kStripes
           << " stripes fully visible)\n";
  }
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
