// `stripemux calibrate`: a good capture set solves to the simulator's truth, and each kind of bad
// set stops with a message naming the pose, device and what to do, exit 2, and leaves an earlier
// rig and report as they were. One set (8 poses at 640 × 480, the example rig) is rendered per
// run (the CTest fixture calibrate.captures, or the first test that needs it); the bad sets are
// copies of it with files removed, copied or altered.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <expected>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "calibration_floor.hpp"
#include "cli_harness.hpp"
#include "smx/algo/lens.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/calib/camera_calibration.hpp"
#include "smx/calib/capture_set.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/sim/png_io.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Vec3 = Eigen::Vector3d;

const fs::path kRig = smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json";
constexpr int kPoses = 8;

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The shared capture set, rendered when the fixture has not.
const fs::path& captures() {
  static const fs::path dir = [] {
    const fs::path d = SMX_CALIBRATE_CAPTURES;
    if (!fs::exists(d / "truth/poses.json")) {
      fs::remove_all(d);
      const auto run = test::runCli({"sim", "--rig", kRig.string(), "--calibration",
                                     std::to_string(kPoses), "--out", d.string()});
      EXPECT_EQ(run.code, 0) << run.err;
    }
    return d;
  }();
  return dir;
}

algo::Rig loadRig(const fs::path& file) {
  auto rig = config::loadRig(file);
  EXPECT_TRUE(rig.has_value()) << file;
  return rig ? *rig : algo::Rig{};
}

sim::RgbImage readPng(const fs::path& file) {
  auto image = sim::readPngRgb8(file);
  EXPECT_TRUE(image.has_value()) << file;
  return image ? *image : sim::RgbImage{};
}

void writePng(const fs::path& file, const sim::RgbImage& image) {
  ASSERT_TRUE(sim::writePngRgb8(file, image.view()).has_value()) << file;
}

// A box blur of `radius` px, `passes` times (three passes approach a Gaussian).
sim::RgbImage blurred(sim::RgbImage image, int radius, int passes) {
  const auto at = [&](int x, int y) -> algo::Rgb8& {
    return image.pixels[static_cast<std::size_t>(y * image.width + x)];
  };
  for (int pass = 0; pass < passes * 2; ++pass) {
    const bool across = pass % 2 == 0;
    sim::RgbImage out = image;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        int r = 0;
        int g = 0;
        int b = 0;
        for (int k = -radius; k <= radius; ++k) {
          const int xx = across ? std::clamp(x + k, 0, image.width - 1) : x;
          const int yy = across ? y : std::clamp(y + k, 0, image.height - 1);
          r += at(xx, yy).r;
          g += at(xx, yy).g;
          b += at(xx, yy).b;
        }
        const int n = 2 * radius + 1;
        out.pixels[static_cast<std::size_t>(y * image.width + x)] = {
            static_cast<std::uint8_t>(r / n), static_cast<std::uint8_t>(g / n),
            static_cast<std::uint8_t>(b / n)};
      }
    }
    image = std::move(out);
  }
  return image;
}

std::string pose(int n) {
  return "pose0" + std::to_string(n);
}

// The stripe coordinate `projector` casts on world point p, when p is in its image.
std::optional<double> stripeAt(const algo::Projector& projector, const Vec3& p) {
  const auto uv = algo::lens::project(projector, {p.x(), p.y(), p.z()});
  if (!uv || uv->x < 0 || uv->y < 0 || uv->x > projector.width - 1 ||
      uv->y > projector.height - 1) {
    return std::nullopt;
  }
  return algo::stripeCoordinate(projector.pattern, projector.width, projector.height, uv->x, uv->y);
}

// The RMS distance (mm) from points on the true projector's stripe surfaces to the same stripe's
// surface of `solved`. The points: a 1 cm grid on the board in every true pose, each
// on the true surface of the stripe coordinate the true projector casts there; the distance is
// the solved coordinate's difference over its gradient.
double planeDistanceRmsMm(const algo::Projector& truth, const algo::Projector& solved,
                          const Json& poses, int cols, int rows, double square) {
  double sum = 0.0;
  int points = 0;
  for (const Json& p : poses.at("poses")) {
    Eigen::Matrix3d R;
    Vec3 t;
    for (int i = 0; i < 9; ++i) {
      R(i / 3, i % 3) = p.at("R").at(static_cast<std::size_t>(i)).get<double>();
    }
    for (int i = 0; i < 3; ++i) {
      t[i] = p.at("t").at(static_cast<std::size_t>(i)).get<double>();
    }
    for (double x = 0.0; x <= (cols - 1) * square; x += 0.01) {
      for (double y = 0.0; y <= (rows - 1) * square; y += 0.01) {
        const Vec3 world = R * Vec3(x, y, 0.0) + t;
        const auto trueStripe = stripeAt(truth, world);
        const auto solvedStripe = stripeAt(solved, world);
        if (!trueStripe || !solvedStripe) {
          continue;
        }
        constexpr double kStepM = 1e-4;
        Vec3 gradient;
        bool inside = true;
        for (int axis = 0; axis < 3 && inside; ++axis) {
          const auto plus = stripeAt(solved, world + kStepM * Vec3::Unit(axis));
          const auto minus = stripeAt(solved, world - kStepM * Vec3::Unit(axis));
          inside = plus && minus;
          gradient[axis] = inside ? (*plus - *minus) / (2 * kStepM) : 0.0;
        }
        if (!inside) {
          continue;
        }
        const double mm = std::abs(*solvedStripe - *trueStripe) / gradient.norm() * 1e3;
        sum += mm * mm;
        ++points;
      }
    }
  }
  EXPECT_GT(points, 100) << "test bug: the board is not in " << truth.id << "'s image";
  return std::sqrt(sum / std::max(points, 1));
}

// The RMS distance (mm) between true board points and where the solved rig places them: the
// true camera pixel of the point, through the solved camera, onto the solved projector's surface
// of the stripe coordinate the true projector casts there (the scanner's triangulation).
double triangulationRmsMm(const algo::Camera& trueCamera, const algo::Projector& truth,
                          const algo::Camera& camera, const algo::Projector& solved,
                          const Json& poses, int cols, int rows, double square) {
  double sum = 0.0;
  int points = 0;
  for (const Json& p : poses.at("poses")) {
    Eigen::Matrix3d R;
    Vec3 t;
    for (int i = 0; i < 9; ++i) {
      R(i / 3, i % 3) = p.at("R").at(static_cast<std::size_t>(i)).get<double>();
    }
    for (int i = 0; i < 3; ++i) {
      t[i] = p.at("t").at(static_cast<std::size_t>(i)).get<double>();
    }
    for (double x = 0.0; x <= (cols - 1) * square; x += 0.01) {
      for (double y = 0.0; y <= (rows - 1) * square; y += 0.01) {
        const Vec3 world = R * Vec3(x, y, 0.0) + t;
        const auto trueStripe = stripeAt(truth, world);
        const auto pixel = algo::lens::project(trueCamera, {world.x(), world.y(), world.z()});
        if (!trueStripe || !pixel) {
          continue;
        }
        const auto ray = algo::lens::pixelRay(camera, *pixel);
        if (!ray) {
          continue;
        }
        const Vec3 o(ray->origin[0], ray->origin[1], ray->origin[2]);
        const Vec3 d(ray->direction[0], ray->direction[1], ray->direction[2]);
        // Secant steps along the ray from the true point's depth to the stripe's surface.
        double a = (world - o).dot(d) - 0.002;
        double b = a + 0.004;
        auto fa = stripeAt(solved, o + a * d);
        auto fb = stripeAt(solved, o + b * d);
        for (int i = 0; i < 20 && fa && fb && *fb != *fa && std::abs(b - a) > 1e-9; ++i) {
          const double c = b - (*fb - *trueStripe) * (b - a) / (*fb - *fa);
          a = b;
          fa = fb;
          b = c;
          fb = stripeAt(solved, o + b * d);
        }
        if (!fb) {
          continue;
        }
        sum += (o + b * d - world).squaredNorm() * 1e6;
        ++points;
      }
    }
  }
  EXPECT_GT(points, 100) << "test bug: the board is not in " << truth.id << "'s image";
  return std::sqrt(sum / std::max(points, 1));
}

class CliCalibrate : public test::CliTest {
 protected:
  // A copy of the shared set to spoil.
  fs::path copy() {
    const fs::path out = dir_ / "captures";
    fs::copy(captures(), out, fs::copy_options::recursive);
    return out;
  }

  // Runs calibrate on `set` over an earlier rig and report; expects exit 2, a message with each
  // of `expected`, and the earlier files as they were with nothing beside them.
  void expectRefused(const fs::path& set, const std::vector<std::string>& expected) {
    const fs::path rig = writeFile("rig.json", "earlier rig\n");
    fs::create_directories(dir_ / "report");
    const fs::path summary = dir_ / "report/summary.txt";
    std::ofstream(summary) << "earlier summary\n";
    const auto before = listing();
    const auto run = test::runCli({"calibrate", "--rig", kRig.string(), "--captures", set.string(),
                                   "--out", rig.string(), "--report", (dir_ / "report").string()});
    EXPECT_EQ(run.code, 2) << run.err;
    EXPECT_EQ(run.out, "");
    for (const std::string& part : expected) {
      EXPECT_NE(run.err.find(part), std::string::npos) << "no \"" << part << "\" in " << run.err;
    }
    EXPECT_NE(run.err.find("nothing written"), std::string::npos) << run.err;
    EXPECT_EQ(readText(rig), "earlier rig\n");
    EXPECT_EQ(readText(summary), "earlier summary\n");
    EXPECT_EQ(listing(), before);
  }

  // Every file under the scratch folder but the captures.
  std::vector<std::string> listing() const {
    std::vector<std::string> out;
    for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
      const std::string name = fs::relative(entry.path(), dir_).generic_string();
      if (!name.starts_with("captures")) {
        out.push_back(name);
      }
    }
    std::ranges::sort(out);
    return out;
  }
};

// Bounds against the truth for the 8-pose set. The camera's focal length and principal point
// within a few tenths of a pixel; the stripe residual within the decoder's noise; the stripe
// surfaces and the triangulated board within a millimetre: the principal point's own error
// (about half a pixel from 7 poses) turns the world frame by about a milliradian, which is most
// of the millimetre at the board's distance. A 2 mm move of a projector takes both past them
// (the solve's own error can lie along a 1 mm move and take a third of it back).
constexpr double kCameraPx = 0.5;
constexpr double kResidualPx = 0.25;
constexpr double kPlaneRmsMm = 0.75;
constexpr double kTriangulationRmsMm = 1.0;

// The solved rig against the truth it was rendered with, computed from the truth's board points
// and the lens and stripe models only; the same checks fail against a truth with proj0 moved
// 2 mm across its stripes.
TEST_F(CliCalibrate, GoodSetSolvesToTheTruth) {
  const fs::path out = dir_ / "rig.json";
  const auto run =
      test::runCli({"calibrate", "--rig", kRig.string(), "--captures", captures().string(), "--out",
                    out.string(), "--report", (dir_ / "report").string()});
  ASSERT_EQ(run.code, 0) << run.err;
  const algo::Rig truth = loadRig(captures() / "truth/rig.json");
  const algo::Rig solved = loadRig(out);
  ASSERT_EQ(solved.cameras.size(), 1U);
  ASSERT_EQ(solved.projectors.size(), 2U);
  EXPECT_NEAR(solved.cameras[0].fx(), truth.cameras[0].fx(), kCameraPx);
  EXPECT_NEAR(solved.cameras[0].cx(), truth.cameras[0].cx(), kCameraPx);
  const Json report = Json::parse(readText(dir_ / "report/report.json"));
  for (const Json& p : report.at("projectors")) {
    EXPECT_LT(p.at("rms_px").get<double>(), kResidualPx) << p.at("id");
  }
  const Json target = Json::parse(readText(captures() / "target.json"));
  const int cols = target.at("inner_corners").at(0).get<int>();
  const int rows = target.at("inner_corners").at(1).get<int>();
  const auto square = target.at("square_m").get<double>();
  const Json poses = Json::parse(readText(captures() / "truth/poses.json"));
  const auto plane = [&](const algo::Projector& trueProjector, std::size_t p) {
    return planeDistanceRmsMm(trueProjector, solved.projectors[p], poses, cols, rows, square);
  };
  const auto triangulation = [&](const algo::Projector& trueProjector, std::size_t p) {
    return triangulationRmsMm(truth.cameras[0], trueProjector, solved.cameras[0],
                              solved.projectors[p], poses, cols, rows, square);
  };
  for (std::size_t p = 0; p < truth.projectors.size(); ++p) {
    EXPECT_LT(plane(truth.projectors[p], p), kPlaneRmsMm) << truth.projectors[p].id;
    EXPECT_LT(triangulation(truth.projectors[p], p), kTriangulationRmsMm) << truth.projectors[p].id;
  }
  algo::Projector moved = truth.projectors[0];
  moved.t[0] += 0.002;  // the device's x axis is across the stripes (angle_deg 0)
  EXPECT_GT(plane(moved, 0), kPlaneRmsMm) << "against the truth: " << plane(truth.projectors[0], 0);
  EXPECT_GT(triangulation(moved, 0), kTriangulationRmsMm)
      << "against the truth: " << triangulation(truth.projectors[0], 0);
}

// The depth scale's uncertainty the report gives (from the joint refinement's covariance) covers
// the solved focal length's actual error, and is no larger than what the corners alone leave
// (OpenCV's estimate): the stripes add measurements of the same target poses.
TEST_F(CliCalibrate, TheReportedScaleUncertaintyCoversTheError) {
  const fs::path out = dir_ / "rig.json";
  const auto run =
      test::runCli({"calibrate", "--rig", kRig.string(), "--captures", captures().string(), "--out",
                    out.string(), "--report", (dir_ / "report").string()});
  ASSERT_EQ(run.code, 0) << run.err;
  const algo::Camera truth = loadRig(captures() / "truth/rig.json").cameras[0];
  const algo::Camera solved = loadRig(out).cameras[0];
  const Json camera = Json::parse(readText(dir_ / "report/report.json")).at("cameras").at(0);
  const auto sdMm = camera.at("depth_scale_sd_mm_at_1m").get<double>();
  const auto sdFx = camera.at("standard_deviation").at("fx").get<double>();
  const double scaleErrorMm =
      ((solved.fx() / truth.fx() + solved.fy() / truth.fy()) / 2 - 1) * 1000;
  EXPECT_GT(sdMm, 0.0);
  EXPECT_LT(std::abs(scaleErrorMm), 3 * sdMm);
  // fx and fy move together, so the scale's sd is close to fx's relative sd.
  EXPECT_NEAR(sdMm, sdFx / solved.fx() * 1000, 0.5 * sdMm);

  const algo::Rig nominal = loadRig(kRig);
  const auto set = calib::openCaptureSet(captures(), nominal);
  ASSERT_TRUE(set.has_value()) << set.error();
  const auto cornersAlone = calib::calibrateCameras(*set, nominal);
  ASSERT_TRUE(cornersAlone.has_value()) << cornersAlone.error();
  EXPECT_LE(sdFx, cornersAlone->cameras[0].sd[0] * 1.01);
}

// The floor of the residual figures: the truth against the corners and stripes measured in the
// captures is the measurement noise alone, small; a rig whose cam0 principal point is 2 px off,
// or whose proj0 is 1 mm off across its stripes, fits the same measurements visibly worse.
TEST_F(CliCalibrate, TheTruthFitsTheMeasurementsToTheirNoise) {
  const algo::Rig truth = loadRig(captures() / "truth/rig.json");
  const host::ResidualFloor floor = host::truthResiduals(captures(), truth);
  EXPECT_GT(floor.cameraRmsPx, 0.0);
  // The corner detector's precision on these captures, which the depth scale's follows: a
  // refinement window of a quarter of the corner spacing gives 0.096 px here.
  EXPECT_LT(floor.cameraRmsPx, 0.08);
  EXPECT_GT(floor.projectorRmsPx, 0.0);
  EXPECT_LT(floor.projectorRmsPx, 0.3);
  algo::Rig shifted = truth;
  shifted.cameras[0].K[2] += 2.0;
  EXPECT_GT(host::truthResiduals(captures(), shifted).cameraRmsPx, 1.0);
  algo::Rig moved = truth;
  moved.projectors[0].t[0] += 0.001;  // across the stripes (angle_deg 0)
  EXPECT_GT(host::truthResiduals(captures(), moved).projectorRmsPx, 2 * floor.projectorRmsPx);
}

TEST_F(CliCalibrate, FewerPosesThanTheMinimum) {
  const fs::path set = copy();
  for (int n = calib::kMinPoses - 1; n < kPoses; ++n) {
    fs::remove_all(set / pose(n));
  }
  expectRefused(set, {std::to_string(calib::kMinPoses - 1) + " pose folders",
                      "at least " + std::to_string(calib::kMinPoses)});
}

// Every projector-off frame shows a blank wall: the target is in none.
TEST_F(CliCalibrate, TargetNeverFound) {
  const fs::path set = copy();
  sim::RgbImage blank = readPng(set / "pose00/cam0.png");
  for (int n = 0; n < kPoses; ++n) {
    const auto level = static_cast<std::uint8_t>(120 + n);  // no two alike: not copies
    std::ranges::fill(blank.pixels, algo::Rgb8{level, level, level});
    writePng(set / pose(n) / "cam0.png", blank);
  }
  expectRefused(set, {"cam0: the target is usable in 0 poses", "pose07: target not found"});
}

TEST_F(CliCalibrate, ProjectorFramesMissingInEveryPose) {
  const fs::path set = copy();
  for (int n = 0; n < kPoses; ++n) {
    fs::remove(set / pose(n) / "proj1.cam0.png");
  }
  expectRefused(set, {"proj1: proj1.cam0.png is missing in every pose (pose00 … pose07)"});
}

// Missing in some poses only: the set opens, without those frames, and says so.
TEST_F(CliCalibrate, ProjectorFramesMissingInSomePosesAreNotes) {
  const fs::path set = copy();
  fs::remove(set / "pose03/proj1.cam0.png");
  const auto opened = calib::openCaptureSet(set, loadRig(kRig));
  ASSERT_TRUE(opened.has_value()) << opened.error();
  EXPECT_TRUE(opened->poses[3].lit[1][0].empty());
  EXPECT_FALSE(opened->poses[4].lit[1][0].empty());
  ASSERT_EQ(opened->notes.size(), 1U);
  EXPECT_NE(opened->notes[0].find("pose03: proj1 frame of cam0 missing"), std::string::npos)
      << opened->notes[0];
}

TEST_F(CliCalibrate, CopiedPoseFolder) {
  const fs::path set = copy();
  fs::remove_all(set / "pose05");
  fs::copy(set / "pose02", set / "pose05");
  expectRefused(set, {"pose05 repeats pose02"});
}

// proj1's frames replaced by the projector-off frames: nothing of it decodes.
TEST_F(CliCalibrate, ProjectorThatLitNothing) {
  const fs::path set = copy();
  for (int n = 0; n < kPoses; ++n) {
    fs::copy_file(set / pose(n) / "cam0.png", set / pose(n) / "proj1.cam0.png",
                  fs::copy_options::overwrite_existing);
  }
  expectRefused(set, {"proj1: no stripe decoded on the target in any pose"});
}

TEST_F(CliCalibrate, ImageOfTheWrongSize) {
  const fs::path set = copy();
  writePng(
      set / "pose04/cam0.png",
      sim::RgbImage{.width = 320, .height = 240, .pixels = std::vector<algo::Rgb8>(320 * 240)});
  expectRefused(set, {"pose04: ", "cam0.png", "320"});
}

TEST_F(CliCalibrate, CorruptPng) {
  const fs::path set = copy();
  const std::string bytes = readText(set / "pose03/proj0.cam0.png");
  std::ofstream(set / "pose03/proj0.cam0.png", std::ios::binary) << bytes.substr(0, 5000);
  expectRefused(set, {"pose03: ", "proj0.cam0.png", "capture this pose again"});
}

// proj0's frames of three pairs of poses swapped: its stripes land where the target was not.
TEST_F(CliCalibrate, ProjectorWhoseStripesDoNotFit) {
  const fs::path set = copy();
  for (const auto& [a, b] : {std::pair{1, 2}, {3, 4}, {6, 7}}) {
    fs::rename(set / pose(a) / "proj0.cam0.png", set / "swap.png");
    fs::rename(set / pose(b) / "proj0.cam0.png", set / pose(a) / "proj0.cam0.png");
    fs::rename(set / "swap.png", set / pose(b) / "proj0.cam0.png");
  }
  expectRefused(set, {"proj0: the solve failed"});
}

// The note the camera fit gives pose `n` of the set when its cam0.png is replaced by `image`.
std::string cameraNote(const fs::path& set, int n, const sim::RgbImage& image) {
  const fs::path file = set / pose(n) / "cam0.png";
  const fs::path kept = set / "kept.png";
  fs::rename(file, kept);
  writePng(file, image);
  const algo::Rig nominal = loadRig(kRig);
  const auto opened = calib::openCaptureSet(set, nominal);
  EXPECT_TRUE(opened.has_value()) << opened.error();
  const auto cameras = opened ? calib::calibrateCameras(*opened, nominal)
                              : std::expected<calib::CamerasFit, std::string>{};
  fs::remove(file);
  fs::rename(kept, file);
  EXPECT_TRUE(cameras.has_value()) << cameras.error();
  if (!cameras) {
    return {};
  }
  const calib::PoseUse& use = cameras->cameras[0].poses[static_cast<std::size_t>(n)];
  EXPECT_FALSE(use.used);
  return use.note;
}

// A defocused pose (σ ≈ 8 px): its corners are not found, and the note says it may be blurred.
// (Milder blur leaves the corners' fit as good as the other poses', and the pose is used.)
TEST_F(CliCalibrate, BlurredPoseIsLeftOut) {
  const fs::path set = copy();
  const std::string note = cameraNote(set, 2, blurred(readPng(set / "pose02/cam0.png"), 8, 3));
  EXPECT_NE(note.find("target not found"), std::string::npos) << note;
  EXPECT_NE(note.find("blurred"), std::string::npos) << note;
}

// The board moved during the exposure: the lower half of the frame 4 px right of the upper. The
// corners are found but fit far worse than the median pose's, and the pose is left out.
TEST_F(CliCalibrate, MovedPoseIsLeftOut) {
  const fs::path set = copy();
  const sim::RgbImage image = readPng(set / "pose04/cam0.png");
  sim::RgbImage moved = image;
  for (int y = image.height / 2; y < image.height; ++y) {
    for (int x = 4; x < image.width; ++x) {
      moved.pixels[static_cast<std::size_t>(y * image.width + x)] =
          image.pixels[static_cast<std::size_t>(y * image.width + x - 4)];
    }
  }
  const std::string note = cameraNote(set, 4, moved);
  EXPECT_NE(note.find("against a median of"), std::string::npos) << note;
  EXPECT_NE(note.find("blurred or moved?"), std::string::npos) << note;
}

}  // namespace
}  // namespace smx::host
