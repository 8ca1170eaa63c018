#include "smx/eval/suite.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "smx/algo/direct_colour.hpp"

namespace smx::eval {

namespace {

using Clock = std::chrono::steady_clock;

// The scene suite: every named scene with the rig it is meant for, and one two-camera rig so
// that pairs of both cameras appear.
struct SceneCase {
  const char* scene;
  const char* rigFile;
  int cameras;
};
constexpr SceneCase kSceneCases[] = {
    {"plane", "rig_2proj_1cam.json", 1},  {"plane", "rig_3proj_1cam.json", 1},
    {"sphere", "rig_2proj_1cam.json", 1}, {"rgbcmy_panel", "rig_2proj_1cam.json", 1},
    {"cups", "rig_2proj_1cam.json", 1},   {"bunny", "rig_2proj_1cam.json", 1},
    {"statue", "rig_3proj_1cam.json", 1}, {"bunny", "rig_3proj_2cam.json", 2},
};

std::string rigLabel(const std::string& file) {
  return file.substr(0, file.find(".json"));
}

// A flat target's region: the smooth lit pixels of the surface at the image centre (truth depth
// within 2 cm of the centre's), so that a wall behind the target is not fitted with it.
Mask targetRegion(const SimFrame& f) {
  Mask m = litRegion(f, {.smooth = true});
  const float centre = f.depth.at(f.depth.width / 2, f.depth.height / 2);
  for (int y = 0; y < m.height; ++y) {
    for (int x = 0; x < m.width; ++x) {
      if (!(std::abs(f.depth.at(x, y) - centre) <= 0.02F)) {
        m.at(x, y) = 0;
      }
    }
  }
  return m;
}

struct Runner {
  const SuiteOptions& options;
  Report& report;

  void note(const std::string& what, Clock::time_point start) const {
    if (options.progress) {
      const double s = std::chrono::duration<double>(Clock::now() - start).count();
      options.progress(what + " (" + std::to_string(std::lround(s * 1000)) + " ms)");
    }
  }
  [[nodiscard]] bool wanted(const std::string& scene) const {
    return options.scenes.empty() ||
           std::ranges::find(options.scenes, scene) != options.scenes.end();
  }
  [[nodiscard]] SimFrame render(const algo::Rig& rig, const sim::Scene& scene, int camera) const {
    return renderSimFrame(
        rig, scene,
        {.camera = camera, .seed = options.seed, .supersampling = options.supersampling});
  }

  void scenes() {
    for (const auto& c : kSceneCases) {
      if (!wanted(c.scene)) {
        continue;
      }
      const auto rig = loadExampleRig(c.rigFile);
      const auto scene = loadNamedScene(c.scene);
      for (int cam = 0; cam < c.cameras; ++cam) {
        const auto start = Clock::now();
        const SimFrame f = render(rig, scene, cam);
        const auto run = runPipeline(f, cam);
        SceneRun s{c.scene,
                   rigLabel(c.rigFile),
                   cam,
                   measureFrame(f, cam, *run->pipeline),
                   depthErrorMapMm(run->pipeline->merged(), f.depth.view()),
                   f.image.width,
                   f.image.height};
        report.scenes.push_back(std::move(s));
        note(std::string("scene ") + c.scene + ", " + rigLabel(c.rigFile) + ", camera " +
                 std::to_string(cam),
             start);
      }
    }
  }

  FlatRun flatTarget(const std::string& label, const algo::Rig& rig, const sim::Scene& scene,
                     double distanceM) const {
    const auto start = Clock::now();
    const SimFrame f = render(rig, scene, 0);
    const auto run = runPipeline(f, 0);
    const Mask region = targetRegion(f);
    FlatRun r{label, distanceM, fitPlane(f.rig.cameras[0], run->pipeline->merged(), region.view()),
              scoreMerged(f, 0, *run->pipeline, region)};
    note("flat target " + label, start);
    return r;
  }

  void flat() {
    if (!wanted("plane")) {
      return;
    }
    const auto plane = loadNamedScene("plane");
    const auto rig2 = loadExampleRig("rig_2proj_1cam.json");
    report.flat.push_back(flatTarget("plane, 2 patterns at 90°", rig2, plane, 0.9));
    auto rig70 = rig2;
    rig70.projectors[1].pattern.angleDeg = 70.0;
    report.flat.push_back(flatTarget("plane, 2 patterns at 70°", rig70, plane, 0.9));
    report.flat.push_back(
        flatTarget("plane, 3 patterns at 60°", loadExampleRig("rig_3proj_1cam.json"), plane, 0.9));
    if (wanted("rgbcmy_panel")) {
      report.flat.push_back(
          flatTarget("RGBCMY panel, 2 patterns", rig2, loadNamedScene("rgbcmy_panel"), 0.9));
    }
    for (const double z : {0.6, 0.75, 0.9, 1.05, 1.2}) {
      auto moved = plane;
      moved.objects.at(0).pose.t.z() = z;
      report.distance.push_back(
          flatTarget("plane at " + std::to_string(z).substr(0, 4) + " m", rig2, moved, z));
    }
  }

  void table2() {
    if (!options.scenes.empty()) {
      return;  // its own scene, not a named one
    }
    const auto start = Clock::now();
    Table2Options table2Options;
    table2Options.seed = options.seed;
    table2Options.supersampling = options.supersampling;
    report.table2 = measureTable2(table2Options);
    note("table 2, " + std::to_string(report.table2.size()) + " configurations", start);
  }

  // Coverage of the camera's whole view (every pixel with a surface) by 1, 2 (and 3)
  // projectors of the same rig: the first n projectors, rendered with only those present.
  void singleProjector() {
    for (const auto& [sceneName, rigFile] :
         {std::pair{"plane", "rig_2proj_1cam.json"}, std::pair{"sphere", "rig_2proj_1cam.json"},
          std::pair{"bunny", "rig_2proj_1cam.json"}, std::pair{"statue", "rig_3proj_1cam.json"}}) {
      if (!wanted(sceneName)) {
        continue;
      }
      const auto full = loadExampleRig(rigFile);
      const auto scene = loadNamedScene(sceneName);
      for (std::size_t n = 1; n <= full.projectors.size(); ++n) {
        const auto start = Clock::now();
        auto rig = full;
        rig.projectors.resize(n);
        const SimFrame f = render(rig, scene, 0);
        const auto run = runPipeline(f, 0);
        Mask view = Mask::filled(f.image.width, f.image.height, 0);
        for (int y = 0; y < view.height; ++y) {
          for (int x = 0; x < view.width; ++x) {
            view.at(x, y) = std::isfinite(f.depth.at(x, y)) ? 255 : 0;
          }
        }
        report.singleProjector.push_back({sceneName, rigLabel(rigFile), static_cast<int>(n),
                                          scoreMerged(f, 0, *run->pipeline, view)});
        note(std::string("coverage ") + sceneName + ", " + std::to_string(n) + " projector(s)",
             start);
      }
    }
  }

  void directColour(const std::string& label, const SimFrame& f, const algo::CameraPipeline& c) {
    const auto& d = c.demux();
    for (int p = 0; p < c.projectors(); ++p) {
      OwnedPlane<algo::Boundary> hue(f.image.width, f.image.height, algo::Boundary{});
      if (auto ok = algo::directColourBoundaries(f.image.view(), d.directions(p), hue.view());
          !ok) {
        throw std::runtime_error(std::string("direct colour: ") + ok.error().message);
      }
      const auto& stripe = f.stripe[static_cast<std::size_t>(p)];
      for (int patterns = 1; patterns <= c.projectors(); ++patterns) {
        const Mask region =
            litRegion(f, {.patterns = patterns, .exactly = true, .smooth = true, .projector = p});
        if (region.count() < 1000) {
          continue;
        }
        report.directColour.push_back(
            {label, p, patterns,
             scoreBoundaries(d.boundaries(p), d.directions(p), stripe.view(), region.view()),
             scoreBoundaries(hue.view(), d.directions(p), stripe.view(), region.view())});
      }
    }
  }

  void trueDirections(const std::string& label, const std::string& rigFile, const SimFrame& f,
                      const PipelineRun& estimated) {
    const auto& c = *estimated.pipeline;
    TrueDirectionRun r{label, rigLabel(rigFile), measureFrame(f, 0, c), {}, {}};
    std::vector<algo::TileDirection> fallback;
    for (int p = 0; p < c.projectors(); ++p) {
      const auto tiles = c.demux().tileDirections(p);
      fallback.insert(fallback.end(), tiles.begin(), tiles.end());
    }
    auto fixed = makePipeline(f.rig, 0, evalPipelineOptions());
    auto& t = *fixed->pipeline;
    const auto tiles = trueTileDirections(f, t.demux().layout(), fallback);
    if (auto ok = t.demux().fixTileDirections(tiles); !ok) {
      throw std::runtime_error(std::string("true directions: ") + ok.error().message);
    }
    if (auto ok = t.run(f.image.view()); !ok) {
      throw std::runtime_error(std::string("pipeline run: ") + ok.error().message);
    }
    r.truth = measureFrame(f, 0, t);
    for (int p = 0; p < c.projectors(); ++p) {
      const Mask region = litRegion(f, {.smooth = true, .projector = p});
      const auto& stripe = f.stripe[static_cast<std::size_t>(p)].view();
      r.boundaries.push_back(
          {label, p, 0,
           scoreBoundaries(c.demux().boundaries(p), c.demux().directions(p), stripe, region.view()),
           scoreBoundaries(t.demux().boundaries(p), t.demux().directions(p), stripe,
                           region.view())});
    }
    report.trueDirections.push_back(std::move(r));
  }

  void baselines() {
    singleProjector();
    struct Case {
      const char* label;
      const char* scene;
      const char* rigFile;
      double angleDeg;  // projector 1's pattern angle, 0: as the rig has it
    };
    for (const auto& k : {Case{"plane, 90°", "plane", "rig_2proj_1cam.json", 0},
                          Case{"plane, 70°", "plane", "rig_2proj_1cam.json", 70},
                          Case{"plane, 3 × 60°", "plane", "rig_3proj_1cam.json", 0},
                          Case{"sphere", "sphere", "rig_2proj_1cam.json", 0},
                          Case{"RGBCMY panel", "rgbcmy_panel", "rig_2proj_1cam.json", 0},
                          Case{"statue", "statue", "rig_3proj_1cam.json", 0}}) {
      if (!wanted(k.scene)) {
        continue;
      }
      const auto start = Clock::now();
      auto rig = loadExampleRig(k.rigFile);
      if (k.angleDeg != 0) {
        rig.projectors[1].pattern.angleDeg = k.angleDeg;
      }
      const SimFrame f = render(rig, loadNamedScene(k.scene), 0);
      const auto run = runPipeline(f, 0);
      directColour(k.label, f, *run->pipeline);
      trueDirections(k.label, k.rigFile, f, *run);
      note(std::string("baselines ") + k.label, start);
    }
  }

  // The median stripe width in camera pixels over the pixels projector 0 lights.
  static double medianStripeWidth(const SimFrame& f) {
    return medianStripeWidthPx(f.stripe.at(0).view(), 2);
  }

  // Generated cases, not named scenes: skipped when the run asks for named scenes only.
  void realism() {
    if (!options.scenes.empty()) {
      return;
    }
    report.realism.cases = options.realismCases;
    report.realism.generator = options.realism;
    for (int i = 0; i < options.realismCases; ++i) {
      const auto start = Clock::now();
      const RealismCase c = generateRealismCase(options.seed, i, options.realism);
      auto runs = runRealismCase(c, options.seed, options.supersampling);
      std::string what = "realism case " + std::to_string(i) + " (" + c.summary + ")";
      for (auto& r : runs) {
        if (r.refused) {
          what += ", cam" + std::to_string(r.camera) + " refused: " + r.reason;
        }
        report.realism.runs.push_back(std::move(r));
      }
      keepWorstImages(report.realism.runs, kRealismWorstShown);
      note(what, start);
    }
  }

  void sweep(Sweep s, const std::vector<double>& values,
             const std::function<void(double, algo::Rig&, sim::Scene&)>& apply) {
    const auto baseRig = loadExampleRig("rig_2proj_1cam.json");
    const auto baseScene = loadNamedScene("sphere");
    for (const double v : values) {
      const auto start = Clock::now();
      auto rig = baseRig;
      auto scene = baseScene;
      apply(v, rig, scene);
      const SimFrame f = render(rig, scene, 0);
      const auto run = runPipeline(f, 0);
      s.points.push_back({v, medianStripeWidth(f), measureFrame(f, 0, *run->pipeline)});
      note("sweep " + s.name + " " + std::to_string(v), start);
    }
    report.sweeps.push_back(std::move(s));
  }

  void sweeps() {
    if (!wanted("sphere")) {
      return;
    }
    const std::string setup = "sphere scene, rig_2proj_1cam";
    sweep({"noise", "camera noise, multiple of the paper's sigma", setup, {}},
          {0.5, 1, 2, 4, 8, 16, 32},
          [](double k, algo::Rig&, sim::Scene& scene) { scene.camera.noiseSigma *= k; });
    sweep({"ambient", "ambient light, % of full scale (projector power 40 %)", setup, {}},
          {0, 10, 20, 40, 60, 80, 120}, [](double pct, algo::Rig&, sim::Scene& scene) {
            scene.lighting.ambient = sim::Vec3::Constant(pct / 100.0);
          });
    sweep(
        {"angle", "angle between the two patterns, deg", setup, {}}, {30, 45, 60, 75, 90},
        [](double deg, algo::Rig& rig, sim::Scene&) { rig.projectors[1].pattern.angleDeg = deg; });
    // Stripe width: scale the projector stripes so that the median width in the camera image
    // (truth) is the value; the reference is the rig's own 6 px stripe.
    SimFrame reference = render(loadExampleRig("rig_2proj_1cam.json"), loadNamedScene("sphere"), 0);
    const double cameraPerProjectorPx =
        medianStripeWidth(reference) / reference.rig.projectors[0].pattern.stripePx;
    sweep({"stripe width", "stripe width in the camera image, pixels (median)", setup, {}},
          {2, 3, 4, 5, 6, 8}, [cameraPerProjectorPx](double px, algo::Rig& rig, sim::Scene&) {
            for (auto& p : rig.projectors) {
              p.pattern.stripePx = px / cameraPerProjectorPx;
            }
          });
    // Albedo saturation: the sphere's albedo from grey towards a strong red of the same
    // brightness in its strongest channel (0.85).
    sweep({"albedo saturation", "sphere albedo saturation (0 grey 0.85, 1 = pure red)", setup, {}},
          {0, 0.25, 0.5, 0.75, 0.9, 1.0}, [](double s, algo::Rig&, sim::Scene& scene) {
            const double other = 0.85 * (1.0 - s);
            scene.objects.at(0).albedo.rgb = sim::Vec3(0.85, other, other);
          });
  }
};

}  // namespace

std::vector<Section> allSections() {
  return {Section::kScenes,    Section::kFlat,   Section::kTable2,
          Section::kBaselines, Section::kSweeps, Section::kRealism};
}

const char* sectionName(Section section) {
  switch (section) {
    case Section::kScenes:
      return "scenes";
    case Section::kFlat:
      return "flat";
    case Section::kTable2:
      return "table2";
    case Section::kBaselines:
      return "baselines";
    case Section::kSweeps:
      return "sweeps";
    case Section::kRealism:
      return "realism";
  }
  return "?";
}

Report runSuite(const SuiteOptions& options) {
  const auto start = Clock::now();
  Report report;
  report.seed = options.seed;
  report.supersampling = options.supersampling;
  Runner runner{options, report};
  for (const Section s : options.sections) {
    switch (s) {
      case Section::kScenes:
        runner.scenes();
        break;
      case Section::kFlat:
        runner.flat();
        break;
      case Section::kTable2:
        runner.table2();
        break;
      case Section::kBaselines:
        runner.baselines();
        break;
      case Section::kSweeps:
        runner.sweeps();
        break;
      case Section::kRealism:
        runner.realism();
        break;
    }
  }
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

std::vector<algo::TileDirection> trueTileDirections(const SimFrame& frame,
                                                    const algo::DemuxLayout& layout,
                                                    std::span<const algo::TileDirection> fallback) {
  const std::size_t tiles = layout.tileCount();
  if (fallback.size() != tiles * static_cast<std::size_t>(layout.projectors)) {
    throw std::invalid_argument("trueTileDirections: fallback needs projectors x tiles entries");
  }
  std::vector<algo::TileDirection> out(fallback.begin(), fallback.end());
  const int tp = layout.params.tilePx;
  // A tile holds a pattern when an eighth of its pixels have a true direction: then its angle
  // is the mean true direction there.
  const int minPixels = std::max(1, tp * tp / 8);
  for (int p = 0; p < layout.projectors; ++p) {
    const auto stripe = frame.stripe.at(static_cast<std::size_t>(p)).view();
    for (int ty = 0; ty < layout.tilesY(); ++ty) {
      for (int tx = 0; tx < layout.tilesX(); ++tx) {
        double sx = 0;
        double sy = 0;
        int n = 0;
        for (int y = ty * tp; y < std::min((ty + 1) * tp, layout.height); ++y) {
          for (int x = tx * tp; x < std::min((tx + 1) * tp, layout.width); ++x) {
            if (const auto g = stripeGradient(stripe, x, y)) {
              sx += g->ux();
              sy += g->uy();
              ++n;
            }
          }
        }
        auto& t = out[static_cast<std::size_t>(p) * tiles +
                      static_cast<std::size_t>(ty * layout.tilesX() + tx)];
        t.present = n >= minPixels ? 1 : 0;
        if (n >= minPixels) {
          t.angle = directionRaw(std::atan2(sy, sx));
        }
      }
    }
  }
  return out;
}

}  // namespace smx::eval
