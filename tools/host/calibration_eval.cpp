#include "calibration_eval.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>

#include "cli.hpp"
#include "smx/algo/lens.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/calib/calibrate.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/eval/frame_eval.hpp"
#include "smx/eval/sim_frame.hpp"
#include "smx/sim/named_scenes.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;
namespace lens = algo::lens;
using Mat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : gen_(seed) {}
  double uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(gen_() >> 11U) * 0x1.0p-53;
  }
  Eigen::Vector3d direction() {
    Eigen::Vector3d v;
    do {
      v = {uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
    } while (v.norm() < 0.1 || v.norm() > 1.0);
    return v.normalized();
  }

 private:
  std::mt19937_64 gen_;
};

Mat3 rotationOf(const algo::DeviceModel& d) {
  return Mat3(d.R.data());
}
Eigen::Vector3d centreOf(const algo::DeviceModel& d) {
  const auto c = lens::centre(d);
  return {c[0], c[1], c[2]};
}

void setPose(algo::DeviceModel& d, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& centre) {
  const Eigen::Vector3d t = -rotation * centre;
  for (int i = 0; i < 9; ++i) {
    d.R[static_cast<std::size_t>(i)] = rotation(i / 3, i % 3);
  }
  d.t = {t[0], t[1], t[2]};
}

// The ranges a built rig differs from its drawing by: a few millimetres and a degree or two of
// mounting, a couple of percent of focal length, the principal point and distortion of a real
// lens. Projector k1 stays within ±0.03: beyond about 0.05 the triangulation tables of these
// rigs refuse the projector (docs/triangulation.md, the 0.1 mm fit).
void perturb(algo::DeviceModel& d, Rng& rng, bool move, double k1Range) {
  // Pixels are square to about 0.1 %: the aspect is taken before fx changes.
  const double aspect = d.fy() / d.fx();
  const double fx = d.fx() * (1 + rng.uniform(-0.02, 0.02));
  d.K[0] = fx;
  d.K[4] = fx * aspect * (1 + rng.uniform(-0.001, 0.001));
  d.K[2] += rng.uniform(-8, 8);
  d.K[5] += rng.uniform(-8, 8);
  d.dist[0] += rng.uniform(-k1Range, k1Range);
  d.dist[1] += rng.uniform(-k1Range / 3, k1Range / 3);
  d.dist[2] += rng.uniform(-0.0005, 0.0005);
  d.dist[3] += rng.uniform(-0.0005, 0.0005);
  if (move) {
    const Eigen::Matrix3d turn(
        Eigen::AngleAxisd(rng.uniform(0.5, 2.0) * std::numbers::pi / 180, rng.direction()));
    const Eigen::Vector3d shift = rng.direction() * rng.uniform(0.002, 0.010);
    setPose(d, turn * rotationOf(d), centreOf(d) + shift);
  }
}

double axesDeg(const algo::DeviceModel& a, const algo::DeviceModel& b) {
  const Mat3 ra = rotationOf(a);
  const Mat3 rb = rotationOf(b);
  double worst = 0;
  for (int i = 0; i < 3; ++i) {
    const double c = std::clamp(ra.row(i).dot(rb.row(i)), -1.0, 1.0);
    worst = std::max(worst, std::acos(c) * 180 / std::numbers::pi);
  }
  return worst;
}

DeviceError cameraError(const algo::Camera& real, const algo::Camera& cal) {
  return {.id = real.id,
          .focalPx = std::abs(cal.fx() - real.fx()),
          .principalPx = std::hypot(cal.cx() - real.cx(), cal.cy() - real.cy()),
          .centreMm = (centreOf(cal) - centreOf(real)).norm() * 1000,
          .centreAlongMm = 0,
          .axesDeg = axesDeg(real, cal),
          .depthRmsMm = 0,
          .depthMaxMm = 0};
}

DeviceError projectorError(const algo::Projector& real, const algo::Projector& cal) {
  const double a = real.pattern.angleDeg * std::numbers::pi / 180;
  const double ca = std::cos(a);
  const double sa = std::sin(a);
  // World direction of the stripes through the centre: every boundary surface contains it.
  const Eigen::Vector3d along =
      (rotationOf(real).transpose() * Eigen::Vector3d(-sa, ca, 0)).normalized();
  const Eigen::Vector3d d = centreOf(cal) - centreOf(real);
  const double alongMm = d.dot(along) * 1000;
  return {.id = real.id,
          .focalPx = std::abs((cal.fx() - real.fx()) * ca * ca + (cal.fy() - real.fy()) * sa * sa),
          .principalPx = std::abs((cal.cx() - real.cx()) * ca + (cal.cy() - real.cy()) * sa),
          .centreMm = (d - along * d.dot(along)).norm() * 1000,
          .centreAlongMm = std::abs(alongMm),
          .axesDeg = axesDeg(real, cal),
          .depthRmsMm = 0,
          .depthMaxMm = 0};
}

std::string fixed(double v, int decimals) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace

algo::Rig drawRealRig(const algo::Rig& nominal, std::uint64_t seed) {
  Rng rng(seed);
  algo::Rig real = nominal;
  for (std::size_t c = 0; c < real.cameras.size(); ++c) {
    perturb(real.cameras[c], rng, c > 0, 0.05);
  }
  for (auto& p : real.projectors) {
    perturb(p, rng, true, 0.03);
  }
  return real;
}

namespace {

// The stripe coordinate the projector throws on a world point, if it lies inside its image.
std::optional<double> stripeAt(const algo::Projector& proj, const lens::Point3& world) {
  const auto q = lens::project(proj, world);
  if (!q || q->x < 0 || q->y < 0 || q->x > proj.width - 1 || q->y > proj.height - 1) {
    return std::nullopt;
  }
  return algo::stripeCoordinate(proj.pattern, proj.width, proj.height, q->x, q->y);
}

// The root of f in [lo, hi] by bisection, when f is defined at both ends and changes sign there.
// Small on purpose: clang-tidy's optional-access analysis grows steeply with a function's loops.
std::optional<double> bisect(const std::function<std::optional<double>(double)>& f, double lo,
                             double hi) {
  const std::optional<double> atLo = f(lo);
  const std::optional<double> atHi = f(hi);
  if (!atLo || !atHi || (*atLo > 0) == (*atHi > 0)) {
    return std::nullopt;
  }
  const bool positiveAtLo = *atLo > 0;
  for (int i = 0; i < 60; ++i) {
    const double mid = (lo + hi) / 2;
    const std::optional<double> atMid = f(mid);
    if (!atMid) {
      break;
    }
    if ((*atMid > 0) == positiveAtLo) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return (lo + hi) / 2;
}

// The depth the calibrated camera and projector give the camera pixel that sees depth z through
// the real ones, if the projector lights it in both.
std::optional<double> calibratedDepth(const algo::Camera& realCamera,
                                      const algo::Projector& realProjector,
                                      const algo::Camera& calCamera,
                                      const algo::Projector& calProjector, lens::Point2 pixel,
                                      double z) {
  const auto local = lens::devicePoint(realCamera, pixel, z);
  if (!local) {
    return std::nullopt;
  }
  const auto s = stripeAt(realProjector, lens::toWorld(realCamera, *local));
  if (!s) {
    return std::nullopt;
  }
  // Where along the calibrated camera's ray for the pixel the stripe coordinate is s.
  const double stripe = *s;
  return bisect(
      [&](double zc) -> std::optional<double> {
        const auto l = lens::devicePoint(calCamera, pixel, zc);
        const auto sc = l ? stripeAt(calProjector, lens::toWorld(calCamera, *l)) : std::nullopt;
        return sc ? std::optional<double>(*sc - stripe) : std::nullopt;
      },
      z * 0.8, z * 1.2);
}

}  // namespace

void measureStripeDepth(const algo::Rig& real, const algo::Rig& calibrated, std::size_t p,
                        DeviceError& error) {
  const algo::Camera& camera = real.cameras[0];
  double sum = 0;
  double signedSum = 0;
  double worst = 0;
  int n = 0;
  constexpr int kStepPx = 16;
  for (int y = kStepPx / 2; y < camera.height; y += kStepPx) {
    for (int x = kStepPx / 2; x < camera.width; x += kStepPx) {
      for (const double z : {0.6, 0.8, 1.0, 1.2}) {
        const auto zc = calibratedDepth(camera, real.projectors[p], calibrated.cameras[0],
                                        calibrated.projectors[p],
                                        {static_cast<double>(x), static_cast<double>(y)}, z);
        if (zc) {
          const double e = (*zc - z) * 1000;
          sum += e * e;
          signedSum += e;
          worst = std::max(worst, std::abs(e));
          ++n;
        }
      }
    }
  }
  error.depthRmsMm = n > 0 ? std::sqrt(sum / n) : 0;
  error.depthMeanMm = n > 0 ? signedSum / n : 0;
  error.depthMaxMm = worst;
}

fs::path renderCalibrationCaptures(const algo::Rig& real, int poses, std::uint64_t seed,
                                   const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path realFile = dir / "real.json";
  std::ofstream(realFile) << config::toJson(real);
  fs::path captures = dir / "captures";
  std::ostringstream out;
  std::ostringstream err;
  const std::vector<std::string> args = {
      "sim",   "--rig",           realFile.string(), "--calibration", std::to_string(poses),
      "--out", captures.string(), "--realism",       "--seed",        std::to_string(seed)};
  if (runCli(args, {out, err}) != kExitOk) {
    throw std::runtime_error("rendering " + std::to_string(poses) + " calibration poses into " +
                             captures.string() + " failed: " + err.str());
  }
  return captures;
}

SceneDepth decodeWithBoth(const algo::Rig& real, const algo::Rig& calibrated,
                          const std::string& scene, std::uint64_t seed) {
  eval::SimRequest request;
  request.seed = seed;
  const eval::SimFrame frame = eval::renderSimFrame(real, eval::loadNamedScene(scene), request);
  const eval::Mask region = eval::litRegion(frame, {.smooth = true});
  const auto realRun = eval::runPipeline(frame, 0);
  auto calRun = eval::makePipeline(calibrated, 0, eval::evalPipelineOptions());
  if (!calRun->pipeline->run(frame.image.view())) {
    throw std::runtime_error(scene + ": the calibrated rig's pipeline failed");
  }
  return {.scene = scene,
          .real = eval::scoreMerged(frame, 0, *realRun->pipeline, region),
          .calibrated = eval::scoreMerged(frame, 0, *calRun->pipeline, region)};
}

std::vector<CalibrationCase> runCalibrationEval(const CalibrationEvalOptions& options) {
  const std::vector<std::string> scenes =
      options.scenes.empty() ? sim::namedScenes() : options.scenes;
  std::vector<CalibrationCase> cases;
  for (std::size_t r = 0; r < options.rigs.size(); ++r) {
    for (const int poses : options.poseCounts) {
      CalibrationCase c;
      c.rig = options.rigs[r];
      c.poses = poses;
      const algo::Rig nominal = eval::loadExampleRig(c.rig);
      const algo::Rig real = drawRealRig(nominal, options.seed * 1000 + r);
      const fs::path dir =
          options.work / (fs::path(c.rig).stem().string() + "-" + std::to_string(poses));
      if (options.progress) {
        options.progress(c.rig + ": rendering " + std::to_string(poses) + " poses");
      }
      const fs::path captures = renderCalibrationCaptures(real, poses, options.seed + r, dir);
      c.floor = truthResiduals(captures, real);
      if (options.progress) {
        options.progress(c.rig + ": solving");
      }
      const auto start = std::chrono::steady_clock::now();
      const auto solved = calib::calibrate(nominal, captures);
      c.solveSeconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!solved) {
        c.failure = solved.error();
        cases.push_back(std::move(c));
        continue;
      }
      c.verdict = solved->verdict;
      std::ofstream(dir / "calibrated.json") << config::toJson(solved->rig);
      for (std::size_t i = 0; i < real.cameras.size(); ++i) {
        c.cameraRmsPx = std::max(c.cameraRmsPx, solved->cameras[i].rmsPx);
        c.cameras.push_back(cameraError(real.cameras[i], solved->rig.cameras[i]));
      }
      for (std::size_t p = 0; p < real.projectors.size(); ++p) {
        c.projectorRmsPx = std::max(c.projectorRmsPx, solved->projectors[p].rmsPx);
        DeviceError e = projectorError(real.projectors[p], solved->rig.projectors[p]);
        measureStripeDepth(real, solved->rig, p, e);
        c.projectors.push_back(e);
      }
      for (const std::string& scene : scenes) {
        if (options.progress) {
          options.progress(c.rig + ": " + scene);
        }
        c.scenes.push_back(decodeWithBoth(real, solved->rig, scene, options.seed));
      }
      cases.push_back(std::move(c));
    }
  }
  return cases;
}

std::string calibrationMarkdown(const std::vector<CalibrationCase>& cases,
                                const std::string& command) {
  std::ostringstream s;
  s << "# Calibration results\n\n"
    << "Generated by `" << command << "`; do not edit. How calibration works and what it "
    << "cannot determine: [calibration.md](calibration.md).\n\n"
    << "For each example rig of `boards/sim`, a real rig is drawn near it (every device but the "
    << "first camera moved 2–10 mm and turned 0.5–2°, focal lengths ±2 %, principal points "
    << "±8 px, lens distortion on cameras and projectors), N poses of the default printed "
    << "target are rendered with the realistic optics (`stripemux sim --calibration N "
    << "--realism`, the paper's noise; every sixth pose partly out of view), and "
    << "`stripemux calibrate` solves them with the example rig as the nominal.\n\n"
    << "## Fits\n\n"
    << "The residual RMS of the fit, and beside it the floor: the real rig and the true target "
    << "poses against the same measured corners and decoded stripes, what the captures' noise "
    << "alone leaves. A fit can only match its floor by fitting noise.\n\n"
    << "| rig | poses | verdict | camera RMS (px) | floor | projector RMS (projector px) | "
       "floor | solve (s) |\n"
    << "|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : cases) {
    if (!c.failure.empty()) {
      s << "| " << c.rig << " | " << c.poses << " | failed: " << c.failure << " | | "
        << fixed(c.floor.cameraRmsPx, 3) << " | | " << fixed(c.floor.projectorRmsPx, 3) << " | "
        << fixed(c.solveSeconds, 0) << " |\n";
      continue;
    }
    s << "| " << c.rig << " | " << c.poses << " | " << c.verdict << " | " << fixed(c.cameraRmsPx, 3)
      << " | " << fixed(c.floor.cameraRmsPx, 3) << " | " << fixed(c.projectorRmsPx, 3) << " | "
      << fixed(c.floor.projectorRmsPx, 3) << " | " << fixed(c.solveSeconds, 0) << " |\n";
  }
  s << "\n## Devices against the real rig\n\n"
    << "Cameras: focal length and principal point (px), centre (mm), largest axis angle (°). "
    << "Projectors: the same across the stripes (along them the stripes tell nothing; the "
    << "centre's error along them is shown apart), and the depth the calibrated rig "
    << "triangulates from exact stripe coordinates minus the true depth, over the first "
    << "camera's image at 0.6–1.2 m (RMS and largest, mm).\n\n"
    << "| rig | poses | device | focal | principal point | centre | centre along stripes | "
       "axes | depth RMS | depth max |\n"
    << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : cases) {
    for (const auto& e : c.cameras) {
      s << "| " << c.rig << " | " << c.poses << " | " << e.id << " | " << fixed(e.focalPx, 2)
        << " | " << fixed(e.principalPx, 2) << " | " << fixed(e.centreMm, 2) << " | | "
        << fixed(e.axesDeg, 3) << " | | |\n";
    }
    for (const auto& e : c.projectors) {
      s << "| " << c.rig << " | " << c.poses << " | " << e.id << " | " << fixed(e.focalPx, 2)
        << " | " << fixed(e.principalPx, 2) << " | " << fixed(e.centreMm, 2) << " | "
        << fixed(e.centreAlongMm, 2) << " | " << fixed(e.axesDeg, 3) << " | "
        << fixed(e.depthRmsMm, 3) << " | " << fixed(e.depthMaxMm, 3) << " |\n";
    }
  }
  s << "\n## Named scenes decoded with the real and the calibrated rig\n\n"
    << "The first camera's frame of each named scene rendered with the real rig, decoded with "
    << "each; merged depth over lit smooth pixels (docs/results.md's \"smooth\" region).\n\n"
    << "| rig | poses | scene | RMSE real (mm) | RMSE calibrated (mm) | ratio | gross real | "
       "gross calibrated | mean error calibrated (mm) |\n"
    << "|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : cases) {
    for (const auto& d : c.scenes) {
      s << "| " << c.rig << " | " << c.poses << " | " << d.scene << " | " << fixed(d.real.rmseMm, 3)
        << " | " << fixed(d.calibrated.rmseMm, 3) << " | "
        << fixed(d.real.rmseMm > 0 ? d.calibrated.rmseMm / d.real.rmseMm : 0, 3) << " | "
        << fixed(100 * d.real.grossRate, 3) << " % | " << fixed(100 * d.calibrated.grossRate, 3)
        << " % | " << fixed(d.calibrated.meanErrorMm, 3) << " |\n";
    }
  }
  return s.str();
}

}  // namespace smx::host
