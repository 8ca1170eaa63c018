// `stripemux sim --calibration N`: the capture layout, determinism per seed, and that the images
// show the printed target where DIR/truth says it is. The truth check is independent of the
// generator: each pixel's ray through the true rig (truth/rig.json, algo/lens.hpp) meets the board
// plane of truth/poses.json, and the documented print (docs/cli.md: the square before the first
// inner corner is black, a white margin of one square) says whether that point is dark or light.
// Small images (160 × 120) keep the renders fast.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cli.hpp"
#include "cli_harness.hpp"
#include "smx/algo/lens.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/sim/png_io.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;
namespace lens = algo::lens;
using Json = nlohmann::json;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

const fs::path kRig2 = smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json";

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

Json readJson(const fs::path& file) {
  return Json::parse(readText(file));
}

// Every regular file under `dir`, relative, sorted.
std::set<std::string> filesUnder(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file()) {
      out.insert(fs::relative(entry.path(), dir).generic_string());
    }
  }
  return out;
}

struct TruthPose {
  Mat3 R;
  Vec3 t;
};

std::vector<TruthPose> readPoses(const fs::path& file) {
  std::vector<TruthPose> out;
  const Json doc = readJson(file);
  for (const auto& p : doc.at("poses")) {
    TruthPose pose;
    for (int i = 0; i < 9; ++i) {
      pose.R(i / 3, i % 3) = p.at("R").at(static_cast<std::size_t>(i)).get<double>();
    }
    for (int i = 0; i < 3; ++i) {
      pose.t[i] = p.at("t").at(static_cast<std::size_t>(i)).get<double>();
    }
    out.push_back(pose);
  }
  return out;
}

// What the printed sheet shows at target point (x, y): its layout as documented, from the target
// file alone.
enum class Print { kDark, kLight, kOff };
Print printAt(double x, double y, int cols, int rows, double square) {
  const auto qx = static_cast<int>(std::floor(x / square)) + 1;  // square column, 0 … cols
  const auto qy = static_cast<int>(std::floor(y / square)) + 1;
  if (qx < -1 || qy < -1 || qx > cols + 1 || qy > rows + 1) {
    return Print::kOff;  // beyond the one-square margin: no paper
  }
  if (qx < 0 || qy < 0 || qx > cols || qy > rows) {
    return Print::kLight;  // the margin
  }
  return (qx + qy) % 2 == 0 ? Print::kDark : Print::kLight;
}

// Target coordinates where the ray through camera pixel (u, v) meets the board plane.
std::optional<Eigen::Vector2d> targetPointAt(const algo::DeviceModel& camera, const TruthPose& pose,
                                             double u, double v) {
  const auto ray = lens::pixelRay(camera, {u, v});
  if (!ray) {
    return std::nullopt;
  }
  const Vec3 o(ray->origin[0], ray->origin[1], ray->origin[2]);
  const Vec3 d(ray->direction[0], ray->direction[1], ray->direction[2]);
  const Vec3 n = pose.R.col(2);
  const double lambda = n.dot(pose.t - o) / n.dot(d);
  if (!(lambda > 0.0)) {
    return std::nullopt;
  }
  const Vec3 local = pose.R.transpose() * (o + lambda * d - pose.t);
  return Eigen::Vector2d(local.x(), local.y());
}

class CliSimCalibration : public test::CliTest {
 protected:
  // The example rig with its camera at a quarter of the resolution (same field of view).
  fs::path smallRig(const std::string& name = "rig.json") {
    Json rig = readJson(kRig2);
    auto& camera = rig["cameras"][0];
    camera["width"] = 160;
    camera["height"] = 120;
    camera["K"] = {200, 0, 79.5, 0, 200, 59.5, 0, 0, 1};
    return writeFile(name, rig.dump());
  }

  test::CliRun capture(const fs::path& out, int poses, int seed,
                       const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"sim",
                                     "--rig",
                                     smallRig().string(),
                                     "--calibration",
                                     std::to_string(poses),
                                     "--out",
                                     out.string(),
                                     "--seed",
                                     std::to_string(seed)};
    args.insert(args.end(), extra.begin(), extra.end());
    return test::runCli(args);
  }
};

// Given 2 poses on a rig with 1 camera and 2 projectors, then exactly the capture layout and the
// truth files are written, each readable as its format says.
TEST_F(CliSimCalibration, WritesTheCaptureLayoutAndTruth) {
  const auto out = dir_ / "caps";
  const auto result = capture(out, 2, 1);
  ASSERT_EQ(result.code, kExitOk) << result.err;
  EXPECT_NE(result.out.find("2 calibration poses"), std::string::npos) << result.out;
  const std::set<std::string> expected = {
      "target.json",      "pose00/cam0.png",       "pose00/proj0.cam0.png", "pose00/proj1.cam0.png",
      "pose01/cam0.png",  "pose01/proj0.cam0.png", "pose01/proj1.cam0.png", "truth/rig.json",
      "truth/poses.json", "truth/scene.json",      "truth/target.png"};
  EXPECT_EQ(filesUnder(out), expected);

  const Json target = readJson(out / "target.json");
  EXPECT_EQ(target.at("format"), "stripemux-target/1");
  EXPECT_EQ(target.at("type"), "checkerboard");
  EXPECT_EQ(target.at("inner_corners"), Json::array({11, 8}));
  EXPECT_EQ(target.at("square_m"), 0.03);

  const Json poses = readJson(out / "truth/poses.json");
  EXPECT_EQ(poses.at("format"), "stripemux-calibration-truth/1");
  ASSERT_EQ(poses.at("poses").size(), 2U);
  EXPECT_EQ(poses["poses"][1].at("pose"), "pose01");
  for (const auto& pose : readPoses(out / "truth/poses.json")) {
    EXPECT_LT((pose.R * pose.R.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_NEAR(pose.R.determinant(), 1.0, 1e-12);
  }

  const auto rig = config::loadRig(out / "truth/rig.json");
  ASSERT_TRUE(rig.has_value()) << rig.error().message();
  EXPECT_EQ(rig->cameras[0].width, 160);
  EXPECT_EQ(rig->cameras[0].K[0], 200.0);
  EXPECT_EQ(rig->projectors.size(), 2U);

  // The scene replays the poses, each held kSceneHoldFrames frames.
  const auto scene = config::loadScene(out / "truth/scene.json");
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  ASSERT_EQ(scene->objects.size(), 1U);
  EXPECT_EQ(scene->objects[0].poseSequence.holdFrames, 30);
  EXPECT_EQ(scene->objects[0].poseSequence.poses.size(), 2U);
  EXPECT_GE(scene->lighting.ambient.x(), 0.35);
  EXPECT_LE(scene->lighting.ambient.x(), 0.6);

  for (const std::string name : {"pose00/cam0.png", "pose01/proj1.cam0.png"}) {
    const auto image = sim::readPngRgb8(out / name);
    ASSERT_TRUE(image.has_value()) << image.error();
    EXPECT_EQ(image->width, 160);
    EXPECT_EQ(image->height, 120);
  }
}

// Given the same seed twice, then every file is the same byte for byte; another seed draws other
// poses.
TEST_F(CliSimCalibration, RenderingIsDeterministicPerSeed) {
  ASSERT_EQ(capture(dir_ / "a", 2, 7).code, kExitOk);
  ASSERT_EQ(capture(dir_ / "b", 2, 7).code, kExitOk);
  ASSERT_EQ(capture(dir_ / "c", 2, 8).code, kExitOk);
  const auto files = filesUnder(dir_ / "a");
  EXPECT_EQ(files, filesUnder(dir_ / "b"));
  for (const auto& f : files) {
    EXPECT_EQ(readText(dir_ / "a" / f), readText(dir_ / "b" / f)) << f;
  }
  EXPECT_NE(readText(dir_ / "a/truth/poses.json"), readText(dir_ / "c/truth/poses.json"));
}

// Given 6 poses, then in every projector-off image each pixel wholly on one printed square (or
// on the margin, or off the sheet) is dark or light as the print at the truth pose says; every
// corner is in view except in pose 5, which is partly out of view; each projector lights the
// board where the camera sees it.
TEST_F(CliSimCalibration, ImagesShowTheTargetWhereTheTruthPutsIt) {
  const auto out = dir_ / "caps";
  const auto result = capture(out, 6, 3);
  ASSERT_EQ(result.code, kExitOk) << result.err;
  const auto rig = config::loadRig(out / "truth/rig.json");
  ASSERT_TRUE(rig.has_value()) << rig.error().message();
  const auto& camera = rig->cameras[0];
  const Json target = readJson(out / "target.json");
  const int cols = target["inner_corners"][0].get<int>();
  const int rows = target["inner_corners"][1].get<int>();
  const double square = target["square_m"].get<double>();
  const auto poses = readPoses(out / "truth/poses.json");
  ASSERT_EQ(poses.size(), 6U);

  for (std::size_t k = 0; k < poses.size(); ++k) {
    const auto& pose = poses[k];
    const std::string dir = "pose0" + std::to_string(k);
    // Corners in view, through the true lens model.
    std::size_t inView = 0;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const Vec3 corner = pose.R * Vec3(c * square, r * square, 0) + pose.t;
        const auto uv = lens::project(camera, {corner.x(), corner.y(), corner.z()});
        inView += uv && uv->x >= 0 && uv->y >= 0 && uv->x <= camera.width - 1 &&
                          uv->y <= camera.height - 1
                      ? 1U
                      : 0U;
      }
    }
    const auto corners = static_cast<std::size_t>(cols * rows);
    if (k == 5) {
      EXPECT_GT(inView, 0U) << dir;
      EXPECT_LT(inView, corners) << dir;
    } else {
      EXPECT_EQ(inView, corners) << dir;
    }

    const auto off = sim::readPngRgb8(out / dir / "cam0.png");
    ASSERT_TRUE(off.has_value()) << off.error();
    std::vector<sim::RgbImage> lit;
    for (const std::string p : {"proj0", "proj1"}) {
      auto image = sim::readPngRgb8(out / dir / (p + ".cam0.png"));
      ASSERT_TRUE(image.has_value()) << image.error();
      lit.push_back(std::move(*image));
    }
    std::array<std::size_t, 2> checked{};
    std::size_t wrong = 0;
    std::array<std::size_t, 2> brighter{};
    std::size_t onSquares = 0;
    for (int y = 0; y < camera.height; ++y) {
      for (int x = 0; x < camera.width; ++x) {
        // The pixel's centre and the corners of a 1.2 px box round it show the same print.
        std::optional<Print> print;
        bool uniform = true;
        bool inside = false;
        for (const auto [dx, dy] :
             {std::array{0.0, 0.0}, std::array{-0.6, -0.6}, std::array{0.6, -0.6},
              std::array{-0.6, 0.6}, std::array{0.6, 0.6}}) {
          const auto p = targetPointAt(camera, pose, x + dx, y + dy);
          const Print here = p ? printAt(p->x(), p->y(), cols, rows, square) : Print::kOff;
          uniform = uniform && (!print || *print == here);
          print = print.value_or(here);
          inside = inside || (p && p->x() > 0 && p->y() > 0 && p->x() < (cols - 1) * square &&
                              p->y() < (rows - 1) * square);
        }
        if (!uniform) {
          continue;
        }
        const auto i = static_cast<std::size_t>(y * camera.width + x);
        const auto& px = off->pixels[i];
        const int sum = px.r + px.g + px.b;
        // White paper under room light of at least 0.35 sums to ~3 · 0.8 · 0.35 · 255 = 214;
        // black paper to at most ~3 · 0.05 · 0.6 · 255 = 23.
        const bool light = sum > 120;
        const bool expectLight = *print == Print::kLight;
        ++checked[expectLight ? 1 : 0];
        wrong += light != expectLight ? 1U : 0U;
        if (expectLight && inside) {
          ++onSquares;
          for (std::size_t p = 0; p < lit.size(); ++p) {
            const auto& q = lit[p].pixels[i];
            brighter[p] += q.r + q.g + q.b > sum + 30 ? 1U : 0U;
          }
        }
      }
    }
    EXPECT_EQ(wrong, 0U) << dir << ": pixels that disagree with the truth pose";
    EXPECT_GT(checked[0], 500U) << dir;
    EXPECT_GT(checked[1], 500U) << dir;
    ASSERT_GT(onSquares, 100U) << dir;
    for (std::size_t p = 0; p < lit.size(); ++p) {
      EXPECT_GT(static_cast<double>(brighter[p]), 0.98 * static_cast<double>(onSquares))
          << dir << " proj" << p;
    }
  }
}

// Given --realism, then the optics of the captures (as truth/scene.json records them) are drawn
// from the documented ranges; without it they are the defaults, with the default noise.
TEST_F(CliSimCalibration, RealismDrawsTheOpticsFromTheirRanges) {
  ASSERT_EQ(capture(dir_ / "plain", 1, 4).code, kExitOk);
  const auto plain = config::loadScene(dir_ / "plain/truth/scene.json");
  ASSERT_TRUE(plain.has_value()) << plain.error().message();
  EXPECT_EQ(plain->camera.responseGamma, 1.0);
  EXPECT_EQ(plain->camera.vignetting, 0.0);
  EXPECT_EQ(plain->lighting.projectorBlackLevel, 0.0);
  EXPECT_EQ(plain->camera.noiseSigma, sim::CameraResponse{}.noiseSigma);

  ASSERT_EQ(capture(dir_ / "real", 1, 4, {"--realism"}).code, kExitOk);
  const auto real = config::loadScene(dir_ / "real/truth/scene.json");
  ASSERT_TRUE(real.has_value()) << real.error().message();
  const auto& c = real->camera;
  const auto& l = real->lighting;
  EXPECT_GT(c.responseGamma, 1.0);
  EXPECT_LE(c.responseGamma, 2.2);
  EXPECT_LE(c.vignetting, 0.4);
  EXPECT_LE(c.defocusSigmaPx, 0.8);
  EXPECT_GE(l.projectorBlackLevel, 0.001);
  EXPECT_LE(l.projectorBlackLevel, 0.02);
  EXPECT_GE(l.projectorGamma, 1.8);
  EXPECT_LE(l.projectorGamma, 2.4);
  EXPECT_EQ(c.noiseSigma, sim::CameraResponse{}.noiseSigma);
  // The same poses: the optics have their own random stream.
  EXPECT_EQ(readText(dir_ / "plain/truth/poses.json"), readText(dir_ / "real/truth/poses.json"));
  EXPECT_NE(readText(dir_ / "plain/pose00/cam0.png"), readText(dir_ / "real/pose00/cam0.png"));
}

TEST_F(CliSimCalibration, BadTargetsAreRefusedNamingTheKeyAndNothingIsWritten) {
  struct Case {
    std::string text;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {R"({"format": "stripemux-target/1", "type": "checkerboard", "inner_corners": [9],
           "square_m": 0.025})",
       "inner_corners: must be an array of 2 numbers"},
      {R"({"format": "stripemux-target/1", "type": "checkerboard", "inner_corners": [9, 2.5],
           "square_m": 0.025})",
       "inner_corners[1]: must be an integer from 3 to 64"},
      {R"({"format": "stripemux-target/1", "type": "checkerboard", "inner_corners": [9, 6],
           "square_m": -1})",
       "square_m: must be positive"},
      {R"({"format": "stripemux-target/1", "type": "checkerboard", "inner_corners": [9, 6],
           "square_m": 2})",
       "square_m: must be from 0.002 to 0.5 m"},
      {R"({"format": "stripemux-target/1", "type": "circles", "inner_corners": [9, 6],
           "square_m": 0.025})",
       "type: must be \"checkerboard\""},
      {R"({"format": "stripemux-target/1", "type": "checkerboard", "inner_corners": [9, 6]})",
       "square_m: required field is missing"},
      {R"({"format": "stripemux-target/1", "type": "checkerboard", "inner_corners": [9, 6],
           "squares_m": 0.025})",
       "unknown key \"squares_m\""},
      {R"({"format": "stripemux-scene/1"})", "format"},
  };
  for (const auto& c : cases) {
    const auto file = writeFile("target.json", c.text);
    const auto out = dir_ / "out";
    const auto result = capture(out, 1, 1, {"--target", file.string()});
    EXPECT_EQ(result.code, kExitBadInput) << c.text;
    EXPECT_NE(result.err.find(c.expected), std::string::npos) << result.err;
    EXPECT_NE(result.err.find(file.string()), std::string::npos) << result.err;
    EXPECT_FALSE(fs::exists(out)) << c.text;
  }
}

TEST_F(CliSimCalibration, UsageErrorsAndARigWithoutSharedViewAreRefused) {
  const auto out = (dir_ / "out").string();
  const auto rig = smallRig().string();
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"sim", "--rig", rig, "--out", out},
           {"sim", "--rig", rig, "--calibration", "0", "--out", out},
           {"sim", "--rig", rig, "--calibration", "100", "--out", out},
           {"sim", "--rig", rig, "--calibration", "2", "--scene", "plane", "--out", out},
           {"sim", "--rig", rig, "--calibration", "2", "--lit", "none", "--out", out},
           {"sim", "--rig", rig, "--scene", "plane", "--realism", "--out", out}}) {
    const auto result = test::runCli(args);
    EXPECT_EQ(result.code, kExitUsage) << result.err;
    EXPECT_FALSE(fs::exists(out));
  }
  // A projector 5 m to the side lights nothing the camera sees at working distance.
  Json moved = readJson(smallRig());
  moved["projectors"][0]["t"] = {5.0, 0.0, 0.0};
  const auto far = writeFile("far.json", moved.dump());
  const auto result =
      test::runCli({"sim", "--rig", far.string(), "--calibration", "1", "--out", out});
  EXPECT_EQ(result.code, kExitBadInput);
  EXPECT_NE(result.err.find("cannot place the target"), std::string::npos) << result.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace smx::host
