// `stripemux scan` against the simulated board (label "sim"): the poses a scan ends with against
// the simulator's truth. The turntable's truth is the scene's own axis (not the rig's, which the
// scan uses) and the steps the table can stand at; the hand-held truth is the scene's trajectory.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "sim_device.hpp"
#include "smx/config/board_json.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/sim/handheld.hpp"
#include "smx/sim/named_scenes.hpp"

namespace smx {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// A board folder on a free loopback port, its capture and network loops running (as stripemuxd
// runs them), cam0 only: half the rendering, and the scan's placement does not need cam1.
config::Board cam0Board(const std::string& folder) {
  config::Board board = test::sourceBoard(folder);
  board.config.cameras.resize(1);
  board.rig.cameras.resize(1);
  return board;
}

class SimBoardDevice : public test::SimDevice {
 public:
  explicit SimBoardDevice(const std::string& folder)
      : test::SimDevice(cam0Board(folder), {.loops = test::SimLoops::kCapture}) {}

  [[nodiscard]] sim::Scene scene() const {
    auto scene = config::loadScene(sim::resolveScene(board().config.sim.scene).value());
    EXPECT_TRUE(scene.has_value());
    return scene.value_or(sim::Scene{});
  }
};

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("smx_scan_sim_test_" + name);
  fs::remove_all(dir);
  return dir;
}

int scan(const std::vector<std::string>& args) {
  std::ostringstream out;
  std::ostringstream err;
  const int code = host::runCli(args, {out, err});
  EXPECT_EQ(code, 0) << out.str() << err.str();
  return code;
}

Json readJson(const fs::path& file) {
  std::ifstream in(file);
  EXPECT_TRUE(in.good()) << file;
  return Json::parse(in, nullptr, false);
}

Eigen::Isometry3d poseOf(const Json& numbers) {
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) {
    m(i / 4, i % 4) = numbers.at(static_cast<std::size_t>(i)).get<double>();
  }
  return Eigen::Isometry3d(m);
}

double angleDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd((a.linear().transpose() * b.linear()).eval()).angle() * 180.0 / M_PI;
}

// The largest distance between where two poses put points a box of half-size `half` round
// `centre` (its corners and centre): the translation error where the object is.
double displacementM(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                     const Eigen::Vector3d& centre, const Eigen::Vector3d& half) {
  double worst = (a * centre - b * centre).norm();
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p = centre + Eigen::Vector3d((corner & 1) != 0 ? half.x() : -half.x(),
                                                       (corner & 2) != 0 ? half.y() : -half.y(),
                                                       (corner & 4) != 0 ? half.z() : -half.z());
    worst = std::max(worst, (a * p - b * p).norm());
  }
  return worst;
}

struct PoseError {
  double rotationDeg = 0;
  double moveMm = 0;
};

// Runs `scan --turntable --views 6 --voxel VOXEL` on the turntable board and returns the largest
// error of the views' final poses against the truth: view k must be the rotation by minus the
// table's angle about the scene's own axis (not the rig's, which the scan uses), the angle being
// that of the step nearest 60k° (steps_per_turn), measured over the bunny's box round the axis.
PoseError turntableScanError(const std::string& voxelMm) {
  SimBoardDevice device("sim-turntable");
  const sim::Scene scene = device.scene();
  EXPECT_TRUE(scene.turntable.has_value());
  EXPECT_TRUE(device.board().config.turntable.has_value());
  if (!scene.turntable || !device.board().config.turntable) {
    return {.rotationDeg = 360, .moveMm = 1e9};
  }
  const Eigen::Vector3d axis = scene.turntable->axis.normalized();
  const Eigen::Vector3d pivot = scene.turntable->pivot;
  const int stepsPerTurn = device.board().config.turntable->stepsPerTurn;

  const fs::path dir = scratch("turntable");
  constexpr int kViews = 6;
  if (scan({"scan", "--device", device.address(), "--turntable", "--views", std::to_string(kViews),
            "--voxel", voxelMm, "--no-colour", "--out", dir.string()}) != 0) {
    return {.rotationDeg = 360, .moveMm = 1e9};
  }
  const Json poses = readJson(dir / "views" / "poses.json");
  EXPECT_TRUE(poses.contains("poses")) << poses.dump();
  EXPECT_EQ(poses.value("poses", Json::array()).size(), static_cast<std::size_t>(kViews));
  // The bunny stands within about 0.2 m of the axis (2.5 × the Stanford bunny).
  const Eigen::Vector3d half(0.1, 0.18, 0.1);
  PoseError worst;
  for (int k = 0; k < kViews && k < std::ssize(poses.value("poses", Json::array())); ++k) {
    const long steps = std::lround(static_cast<double>(stepsPerTurn) * k / kViews);
    const double tableDeg = 360.0 * static_cast<double>(steps) / stepsPerTurn;
    const Eigen::Isometry3d truth = Eigen::Translation3d(pivot) *
                                    Eigen::AngleAxisd(-tableDeg * M_PI / 180.0, axis) *
                                    Eigen::Translation3d(-pivot);
    const Json& view = poses["poses"][static_cast<std::size_t>(k)];
    const Eigen::Isometry3d pose = poseOf(view["pose"]);
    const double rotationDeg = angleDeg(pose, truth);
    const double moveMm = displacementM(pose, truth, pivot, half) * 1e3;
    worst.rotationDeg = std::max(worst.rotationDeg, rotationDeg);
    worst.moveMm = std::max(worst.moveMm, moveMm);
    std::printf("view %s at %.4f°: %.3f° and %.3f mm from the truth\n",
                view["id"].get<std::string>().c_str(), tableDeg, rotationDeg, moveMm);
  }
  fs::remove_all(dir);
  return worst;
}

// Given the turntable board, when `scan --turntable --views 6` runs, then every view is placed
// by the turn the table made about its true axis, within the 0.2° and 1 mm: the views are
// placed by the rig's (calibrated) axis and the device's angles. A view placed by the wrong turn
// or the wrong sign is off by many degrees.
TEST(ScanSim, TurntablePosesAreTheTurnsAboutTheTrueAxis) {
  const PoseError error = turntableScanError("2");
  EXPECT_LT(error.rotationDeg, 0.2);
  EXPECT_LT(error.moveMm, 1.0);
}

// Given the hand-held board (the rig carried round a head), when `scan --handheld --frames 15`
// runs, then every fused view's pose in views.json is the rig's true motion since the first
// fused view: T(f0)⁻¹·T(f), T the scene's trajectory and f the device's frame number (the id).
TEST(ScanSim, HandheldPosesFollowTheTrueTrajectory) {
  SimBoardDevice device("sim-handheld");
  const sim::Scene scene = device.scene();
  ASSERT_TRUE(scene.handheld.has_value());
  const sim::Handheld& hand = *scene.handheld;

  const fs::path dir = scratch("handheld");
  ASSERT_EQ(scan({"scan", "--device", device.address(), "--handheld", "--frames", "15", "--voxel",
                  "2", "--out", dir.string()}),
            0);
  const Json views = readJson(dir / "views" / "views.json");
  ASSERT_TRUE(views.contains("views")) << views.dump();
  ASSERT_GE(views["views"].size(), 10U) << "most captures of a slow orbit must be fused";
  const auto frameOf = [](const Json& view) {
    return std::stod(view["id"].get<std::string>());  // the device's frame number
  };
  const Eigen::Isometry3d first = sim::handheldRigPose(hand, frameOf(views["views"][0]));
  const Eigen::Vector3d half(0.1, 0.12, 0.1);  // a head at the orbit's centre
  for (const Json& view : views["views"]) {
    ASSERT_TRUE(view.contains("pose")) << view.dump();
    const double f = frameOf(view);
    const Eigen::Isometry3d truth = first.inverse() * sim::handheldRigPose(hand, f);
    const Eigen::Isometry3d pose = poseOf(view["pose"]);
    // The head is at the orbit's centre, in the first fused view's rig frame.
    const Eigen::Vector3d head = first.inverse() * hand.centre;
    const double rotationDeg = angleDeg(pose, truth);
    const double moveMm = displacementM(pose, truth, head, half) * 1e3;
    EXPECT_LT(rotationDeg, 0.2) << "frame " << f;
    EXPECT_LT(moveMm, 1.0) << "frame " << f;
    std::printf("frame %.0f: %.3f° and %.3f mm from the truth\n", f, rotationDeg, moveMm);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace smx
