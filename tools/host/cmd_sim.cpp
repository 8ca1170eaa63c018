// stripemux sim --rig rig.json --scene scene.json|NAME --out DIR [--frames N] [--seed S]
//               [--lit all|none|ID,ID...] [--no-truth]
// stripemux sim --rig rig.json --calibration N --out DIR [--seed S] [--target target.json]
//               [--realism]
// stripemux sim --rig rig.json --table-calibration N --out DIR [--seed S] [--target …] [--realism]
// Renders what each camera of the rig sees, with ground truth, or calibration captures of a
// checkerboard: free-standing, or leaning on a turntable (docs/simulator.md, docs/cli.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <expected>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "output_files.hpp"
#include "sim_calibration.hpp"
#include "sim_table_calibration.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/sim/named_scenes.hpp"
#include "smx/sim/pfm_io.hpp"
#include "smx/sim/png_io.hpp"
#include "smx/sim/renderer.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

struct SimOptions {
  fs::path rig;
  std::string scene;
  fs::path out;
  int frames = 1;
  std::uint64_t seed = 1;
  std::string lit = "all";
  bool noTruth = false;
  int calibration = 0;       // poses; 0: render the scene instead
  int tableCalibration = 0;  // table angles; 0: none
  fs::path target;           // empty: the default calib::Target
  bool realism = false;
};

std::expected<std::vector<bool>, std::string> parseLit(const std::string& spec,
                                                       const algo::Rig& rig) {
  std::vector<bool> lit(rig.projectors.size(), spec == "all");
  if (spec == "all" || spec == "none") {
    return lit;
  }
  std::stringstream ss(spec);
  for (std::string id; std::getline(ss, id, ',');) {
    bool found = false;
    for (std::size_t i = 0; i < rig.projectors.size(); ++i) {
      if (rig.projectors[i].id == id) {
        lit[i] = true;
        found = true;
      }
    }
    if (!found) {
      return std::unexpected("--lit: the rig has no projector \"" + id + "\"");
    }
  }
  return lit;
}

template <class T>
struct Plane {
  std::vector<T> pixels;
  algo::ImageView<T> view;
  Plane(int w, int h, T fill)
      : pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill),
        view(*algo::ImageView<T>::packed(pixels, w, h)) {}
};

struct CameraTruth {
  Plane<float> depth;
  Plane<std::array<float, 3>> normal;
  std::vector<Plane<std::uint8_t>> lit;
  std::vector<Plane<float>> u, v, stripe;

  CameraTruth(int w, int h, std::size_t projectors)
      : depth(w, h, 0.0F), normal(w, h, std::array<float, 3>{}) {
    for (std::size_t p = 0; p < projectors; ++p) {
      lit.emplace_back(w, h, std::uint8_t{0});
      u.emplace_back(w, h, 0.0F);
      v.emplace_back(w, h, 0.0F);
      stripe.emplace_back(w, h, 0.0F);
    }
  }

  sim::GroundTruthViews views() {
    sim::GroundTruthViews t{depth.view, normal.view, {}};
    for (std::size_t p = 0; p < lit.size(); ++p) {
      t.projectors.push_back({lit[p].view, u[p].view, v[p].view, stripe[p].view});
    }
    return t;
  }
};

template <class Pixel>
std::expected<void, std::string> writePlane(OutputFolder& out, const std::string& name,
                                            const Plane<Pixel>& plane) {
  return writePfm<Pixel>(out, name, plane.view);
}

std::expected<void, std::string> writeTruth(CameraTruth& truth, const algo::Rig& rig,
                                            OutputFolder& out, const std::string& camTag) {
  if (auto r = writePlane(out, camTag + ".depth.pfm", truth.depth); !r) {
    return r;
  }
  if (auto r = writePlane(out, camTag + ".normal.pfm", truth.normal); !r) {
    return r;
  }
  for (std::size_t p = 0; p < rig.projectors.size(); ++p) {
    const auto base = rig.projectors[p].id + "." + camTag;
    if (auto r = writePngGray8(out, base + ".lit.png", truth.lit[p].view); !r) {
      return r;
    }
    for (const auto& [suffix, plane] :
         {std::pair{".u.pfm", &truth.u[p]}, std::pair{".v.pfm", &truth.v[p]},
          std::pair{".stripe.pfm", &truth.stripe[p]}}) {
      if (auto r = writePlane(out, base + suffix, *plane); !r) {
        return r;
      }
    }
  }
  return {};
}

int runSim(const SimOptions& opts, const CliStreams& io) {
  const auto fail = [&](int code, const std::string& message) {
    io.err << "stripemux sim: " << message << "\n";
    return code;
  };
  auto rig = config::loadRig(opts.rig);
  if (!rig) {
    return fail(kExitBadInput, rig.error().message());
  }
  const auto scenePath = sim::resolveScene(opts.scene);
  if (!scenePath) {
    return fail(kExitBadInput, scenePath.error());
  }
  auto scene = config::loadScene(*scenePath);
  if (!scene) {
    return fail(kExitBadInput, scene.error().message());
  }
  const auto lit = parseLit(opts.lit, *rig);
  if (!lit) {
    return fail(kExitUsage, lit.error());
  }
  auto renderer = sim::Renderer::create(*rig, *scene);
  if (!renderer) {
    return fail(kExitBadInput, renderer.error());
  }
  auto out = OutputFolder::create(opts.out);
  if (!out) {
    return fail(kExitDeviceOrIo, out.error());
  }
  // Printed once the files are in place.
  std::ostringstream report;

  for (int frame = 0; frame < opts.frames; ++frame) {
    for (std::size_t c = 0; c < rig->cameras.size(); ++c) {
      const auto& camera = rig->cameras[c];
      const std::string tag = opts.frames > 1 ? camera.id + "_" + std::to_string(frame) : camera.id;
      const Plane<algo::Rgb8> image(camera.width, camera.height, algo::Rgb8{0, 0, 0});
      std::unique_ptr<CameraTruth> truth;
      sim::GroundTruthViews truthViews;
      if (!opts.noTruth) {
        truth = std::make_unique<CameraTruth>(camera.width, camera.height, rig->projectors.size());
        truthViews = truth->views();
      }
      const sim::FrameRequest request{static_cast<int>(c), frame, *lit, opts.seed};
      const auto start = std::chrono::steady_clock::now();
      if (auto r = (*renderer)->render(request, image.view, truth ? &truthViews : nullptr); !r) {
        return fail(kExitBadInput, camera.id + ": " + r.error());
      }
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      if (auto r = writePngRgb8(*out, tag + ".png", image.view); !r) {
        return fail(kExitDeviceOrIo, r.error());
      }
      if (truth) {
        if (auto r = writeTruth(*truth, *rig, *out, tag); !r) {
          return fail(kExitDeviceOrIo, r.error());
        }
      }
      report << "wrote " << out->pathOf(tag + ".png").string() << "  (frame " << frame << ", "
             << camera.width << "x" << camera.height << ", rendered in "
             << static_cast<int>(std::lround(ms)) << " ms" << (truth ? ", with ground truth" : "")
             << ")\n";
    }
  }
  if (auto committed = out->commit(); !committed) {
    return fail(kExitDeviceOrIo, committed.error());
  }
  io.out << report.str();
  return kExitOk;
}

// Noise seed of one lit state of a pose (0: every projector off, 1 + p: projector p alone), so
// that the frames of a pose do not share their noise.
std::uint64_t litSeed(std::uint64_t seed, std::size_t state) {
  return seed + state * 0x9E3779B97F4A7C15ULL;
}

// DIR/target.json, and in DIR/truth rig.json, poses.json, scene.json and target.png.
std::expected<void, std::string> writeCalibrationTruth(OutputFolder& top, OutputFolder& truth,
                                                       const algo::Rig& rig,
                                                       const calib::Target& target,
                                                       const std::vector<TargetPose>& poses,
                                                       const sim::Scene& scene) {
  sim::Scene held = scene;
  held.objects.front().poseSequence.holdFrames = kSceneHoldFrames;
  const TargetSheet sheet = targetSheet(target);
  Plane<std::uint8_t> sheetImage(sheet.width, sheet.height, 0);
  std::copy(sheet.grey.begin(), sheet.grey.end(), sheetImage.pixels.begin());
  if (auto r = top.writeText("target.json", targetJson(target)); !r) {
    return r;
  }
  if (auto r = truth.writeText("rig.json", config::toJson(rig)); !r) {
    return r;
  }
  if (auto r = truth.writeText("poses.json", targetPosesJson(poses)); !r) {
    return r;
  }
  if (auto r = truth.writeText("scene.json", calibrationSceneJson(held)); !r) {
    return r;
  }
  return writePngGray8(truth, "target.png", sheetImage.view);
}

// Every camera's images of one pose: projectors off, then each projector alone. Errors carry
// their exit code.
std::expected<void, std::pair<int, std::string>> renderCalibrationPose(sim::Renderer& renderer,
                                                                       const algo::Rig& rig,
                                                                       int pose, std::uint64_t seed,
                                                                       bool projectorsOffOnly,
                                                                       OutputFolder& folder) {
  const std::size_t states = projectorsOffOnly ? 0 : rig.projectors.size();
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    const auto& camera = rig.cameras[c];
    for (std::size_t state = 0; state <= states; ++state) {
      std::vector<bool> lit(rig.projectors.size(), false);
      std::string name;
      if (state > 0) {
        lit[state - 1] = true;
        name = rig.projectors[state - 1].id;
        name += '.';
      }
      name += camera.id;
      name += ".png";
      const Plane<algo::Rgb8> image(camera.width, camera.height, algo::Rgb8{0, 0, 0});
      const sim::FrameRequest request{static_cast<int>(c), pose, lit, litSeed(seed, state)};
      if (auto r = renderer.render(request, image.view, nullptr); !r) {
        return std::unexpected(std::pair{kExitBadInput, camera.id + ": " + r.error()});
      }
      if (auto r = writePngRgb8(folder, name, image.view); !r) {
        return std::unexpected(std::pair{kExitDeviceOrIo, r.error()});
      }
    }
  }
  return {};
}

// The capture layout of docs/cli.md; nothing is left behind when a step fails.
int runCalibration(const SimOptions& opts, const CliStreams& io) {
  const auto fail = [&](int code, const std::string& message) {
    io.err << "stripemux sim: " << message << "\n";
    return code;
  };
  auto rig = config::loadRig(opts.rig);
  if (!rig) {
    return fail(kExitBadInput, rig.error().message());
  }
  calib::Target target = kDefaultCalibrationTarget;
  if (!opts.target.empty()) {
    auto loaded = calib::loadTarget(opts.target);
    if (!loaded) {
      return fail(kExitBadInput, loaded.error());
    }
    target = *loaded;
  }
  // A turntable's captures: the target leaning on the table at each angle, projectors off.
  const bool table = opts.tableCalibration > 0;
  const int count = table ? opts.tableCalibration : opts.calibration;
  const TableLine line = defaultTableLine(*rig);
  const std::vector<double> angles = tableAngles(opts.tableCalibration);
  const auto poses = table ? std::expected<std::vector<TargetPose>, std::string>(
                                 tableTargetPoses(target, line, angles))
                           : drawTargetPoses(*rig, target, opts.calibration, opts.seed);
  if (!poses) {
    return fail(kExitBadInput, poses.error());
  }
  // One frame per pose here; the scene file holds each pose for a while.
  const sim::Scene scene = calibrationScene(target, *poses, 1, opts.seed, opts.realism);
  auto renderer = sim::Renderer::create(*rig, scene);
  if (!renderer) {
    return fail(kExitBadInput, renderer.error());
  }
  // Declared first, destroyed last: a failed run removes the subfolders before DIR.
  auto top = OutputFolder::create(opts.out);
  if (!top) {
    return fail(kExitDeviceOrIo, top.error());
  }
  std::vector<fs::path> dirs = {opts.out / "truth"};
  for (int pose = 0; pose < count; ++pose) {
    dirs.push_back(opts.out / (table ? tableViewName(pose) : poseDirName(pose)));
  }
  std::vector<OutputFolder> folders;  // truth, then one per pose
  for (const auto& dir : dirs) {
    auto folder = OutputFolder::create(dir);
    if (!folder) {
      return fail(kExitDeviceOrIo, folder.error());
    }
    folders.push_back(std::move(*folder));
  }
  if (auto r = writeCalibrationTruth(*top, folders[0], *rig, target, *poses, scene); !r) {
    return fail(kExitDeviceOrIo, r.error());
  }
  if (table) {
    if (auto r = top->writeText("turntable.json", tableCapturesJson(angles)); !r) {
      return fail(kExitDeviceOrIo, r.error());
    }
    if (auto r = folders[0].writeText("axis.json", tableLineJson(line)); !r) {
      return fail(kExitDeviceOrIo, r.error());
    }
  }
  const auto start = std::chrono::steady_clock::now();
  for (int pose = 0; pose < count; ++pose) {
    auto& folder = folders[static_cast<std::size_t>(pose) + 1];
    if (auto r = renderCalibrationPose(**renderer, *rig, pose, opts.seed, table, folder); !r) {
      return fail(r.error().first, r.error().second);
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (auto r = top->commit(); !r) {
    return fail(kExitDeviceOrIo, r.error());
  }
  for (auto& folder : folders) {
    if (auto r = folder.commit(); !r) {
      return fail(kExitDeviceOrIo, r.error());
    }
  }
  io.out << "wrote " << count << (table ? " turntable angles" : " calibration poses") << " of a "
         << target.cols << "x" << target.rows << " checkerboard to " << opts.out.string() << " ("
         << rig->cameras.size() * (1 + (table ? 0 : rig->projectors.size()))
         << " images per pose, rendered in " << std::lround(seconds) << " s; truth in "
         << (opts.out / "truth").string() << ")\n";
  return kExitOk;
}

}  // namespace

void addSimCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<SimOptions>();
  auto* cmd =
      app.add_subcommand("sim",
                         "Render what the rig's cameras see of a scene, with ground truth, or "
                         "calibration captures of a checkerboard");
  cmd->add_option("--rig", opts->rig, "Rig description (stripemux-rig/1 JSON)")->required();
  auto* scene =
      cmd->add_option("--scene", opts->scene,
                      "Scene file (stripemux-scene/1 JSON) or the name of a built-in scene");
  auto* calibration =
      cmd->add_option("--calibration", opts->calibration,
                      "Render calibration captures of a checkerboard in N poses instead of a scene")
          ->check(CLI::Range(1, 99));
  scene->excludes(calibration);
  auto* tableCalibration =
      cmd->add_option("--table-calibration", opts->tableCalibration,
                      "Render captures of a checkerboard leaning on a turntable at N angles "
                      "(projectors off) for the table's axis")
          ->check(CLI::Range(1, 99));
  scene->excludes(tableCalibration);
  calibration->excludes(tableCalibration);
  cmd->add_option("--target", opts->target,
                  "Calibration target (stripemux-target/1 JSON); default 9x6 corners, 25 mm")
      ->excludes(scene);
  cmd->add_flag("--realism", opts->realism,
                "Calibration captures with realistic optics drawn from their documented ranges")
      ->excludes(scene);
  cmd->add_option("--out", opts->out, "Output directory")->required();
  cmd->add_option("--frames", opts->frames, "Number of frames (animated scenes move)")
      ->check(CLI::Range(1, 100000))
      ->excludes(calibration)
      ->excludes(tableCalibration);
  cmd->add_option("--seed", opts->seed, "Noise seed");
  cmd->add_option("--lit", opts->lit, "Projectors on: all, none, or a comma-separated id list")
      ->excludes(calibration)
      ->excludes(tableCalibration);
  cmd->add_flag("--no-truth", opts->noTruth, "Write only the camera images")
      ->excludes(calibration)
      ->excludes(tableCalibration);
  cmd->callback([opts, &io, &exitCode] {
    if (opts->calibration == 0 && opts->tableCalibration == 0 && opts->scene.empty()) {
      io.err << "stripemux sim: give --scene, or --calibration N or --table-calibration N for "
                "calibration captures\n";
      exitCode = kExitUsage;
      return;
    }
    exitCode = opts->calibration > 0 || opts->tableCalibration > 0 ? runCalibration(*opts, io)
                                                                   : runSim(*opts, io);
  });
}

}  // namespace smx::host
