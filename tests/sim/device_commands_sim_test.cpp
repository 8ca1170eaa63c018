// `stripemux check --device` and `stripemux calibrate --device` against the simulated board
// (label "sim"). The board renders with the true rig and announces another (the rig.json it was
// given), as a rig that drifted since its calibration does: the check must flag the difference,
// and the calibration must find the true rig from the announced one.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "sim_device.hpp"
#include "smx/config/rig_json.hpp"
#include "source_dir.hpp"

namespace smx {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kSource = test::sourceDir();

struct CliRun {
  int code;
  std::string out;
  std::string err;
};

CliRun cli(const std::vector<std::string>& args) {
  std::ostringstream out;
  std::ostringstream err;
  const int code = host::runCli(args, {out, err});
  return {code, out.str(), err.str()};
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("smx_device_commands_sim_test_" + name);
  fs::remove_all(dir);
  return dir;
}

// boards/sim rendering `scene` with `rendered`, announcing `announced`, on a free loopback port.
// Only raw captures are served (no range stream), so the simulated camera's frame k is the k-th
// raw capture: a scene's pose_sequence advances one frame per capture.
class RenderingDevice : public test::SimDevice {
 public:
  RenderingDevice(const std::string& scene, const algo::Rig& rendered, const algo::Rig& announced)
      : test::SimDevice(test::renderingScene(test::sourceBoard("sim"), scene, announced),
                        {.loops = test::SimLoops::kServe, .renderedRig = rendered}) {}
};

algo::Rig loadRig(const fs::path& file) {
  auto rig = config::loadRig(file);
  EXPECT_TRUE(rig.has_value()) << file;
  return rig.value_or(algo::Rig{});
}

// The projector's centre in the world frame, C = -Rᵀ·t.
std::array<double, 3> centre(const algo::DeviceModel& d) {
  std::array<double, 3> c{};
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) {
      c[static_cast<std::size_t>(i)] -=
          d.R[static_cast<std::size_t>(k * 3 + i)] * d.t[static_cast<std::size_t>(k)];
    }
  }
  return c;
}

double distanceMm(const algo::DeviceModel& a, const algo::DeviceModel& b) {
  const auto ca = centre(a);
  const auto cb = centre(b);
  return 1000 * std::hypot(ca[0] - cb[0], ca[1] - cb[1], ca[2] - cb[2]);
}

// `rig` with the projector moved by `metres` along its own x (axis 0) or y (axis 1). Across its
// stripes, so that the move shows: along them it leaves every stripe plane where it was.
algo::Rig withProjectorMoved(algo::Rig rig, std::size_t projector, std::size_t axis,
                             double metres) {
  rig.projectors[projector].t.at(axis) -= metres;
  return rig;
}

// Given a device rendering a plane with the rig it announces, `check --device` calls every
// projector good (exit 0); given one whose announced rig has proj0 2 mm off where it is
// rendered, the check names proj0 as drifted (exit 4). Two cameras, so the projector is named.
TEST(DeviceCommandsSim, CheckOnADeviceFlagsAProjectorItsRigMisplaces) {
  const algo::Rig truth = loadRig(kSource / "boards/sim/rig_2proj_2cam.json");
  {
    const RenderingDevice device("plane", truth, truth);
    const fs::path report = scratch("check_good");
    const auto run = cli({"check", "--device", device.address(), "--report", report.string()});
    EXPECT_EQ(run.code, host::kExitOk) << run.err << run.out;
    EXPECT_NE(run.out.find("good: all 2 projectors agree"), std::string::npos) << run.out;
    EXPECT_TRUE(fs::exists(report / "check.json"));
  }
  const RenderingDevice device("plane", truth, withProjectorMoved(truth, 0, 0, 0.002));
  const auto run = cli({"check", "--device", device.address(), "--json"});
  EXPECT_EQ(run.code, 4) << run.err << run.out;
  const auto json = Json::parse(run.out, nullptr, false);
  ASSERT_FALSE(json.is_discarded()) << run.out;
  EXPECT_FALSE(json["healthy"].get<bool>());
  EXPECT_EQ(json["projectors"][0]["verdict"], "drifted");
  EXPECT_EQ(json["projectors"][1]["verdict"], "good");
  EXPECT_EQ(json["summary"], "drifted: proj0 (recalibrate)");
}

// --device with --rig, the offline form without --captures, or a malformed address is a usage
// error, as is a captures folder that holds an earlier session's poses; a device that is not
// there is exit 3, and no RIG.json is written.
TEST(DeviceCommandsSim, WrongOptionsAreUsageErrorsAndNoDeviceIsExit3) {
  const std::string rig = (kSource / "boards/sim/rig_2proj_1cam.json").string();
  EXPECT_EQ(cli({"calibrate", "--device", "127.0.0.1:1", "--rig", rig, "--out", "x.json"}).code,
            host::kExitUsage);
  EXPECT_EQ(cli({"calibrate", "--rig", rig, "--out", "x.json"}).code, host::kExitUsage);
  EXPECT_EQ(
      cli({"calibrate", "--rig", rig, "--captures", "c", "--poses", "6", "--out", "x.json"}).code,
      host::kExitUsage);
  EXPECT_EQ(cli({"check", "--device", "127.0.0.1:1", "--rig", rig}).code, host::kExitUsage);
  EXPECT_EQ(cli({"check", "--images", "frame"}).code, host::kExitUsage);
  EXPECT_EQ(cli({"check", "--device", "10.0.0.2:99999"}).code, host::kExitUsage);
  EXPECT_EQ(cli({"calibrate", "--device", "10.0.0.2:", "--out", "x.json"}).code, host::kExitUsage);

  const fs::path out = scratch("nobody");
  const auto noTarget =
      cli({"calibrate", "--device", "127.0.0.1:1", "--out", (out / "rig.json").string()});
  EXPECT_EQ(noTarget.code, host::kExitUsage);
  EXPECT_NE(noTarget.err.find("no target: give --target COLSxROWS and --square M"),
            std::string::npos)
      << noTarget.err;
  const auto nobody = cli({"calibrate", "--device", "127.0.0.1:1", "--target", "9x6", "--square",
                           "0.03", "--out", (out / "rig.json").string()});
  EXPECT_EQ(nobody.code, host::kExitDeviceOrIo) << nobody.err;
  EXPECT_FALSE(fs::exists(out / "rig.json"));
  EXPECT_EQ(cli({"check", "--device", "127.0.0.1:1"}).code, host::kExitDeviceOrIo);

  // Captures of an earlier session are not mixed with new ones.
  fs::create_directories(out / "rig.captures/pose00");
  const auto earlier = cli({"calibrate", "--device", "127.0.0.1:1", "--target", "9x6", "--square",
                            "0.03", "--out", (out / "rig.json").string()});
  EXPECT_EQ(earlier.code, host::kExitUsage);
  EXPECT_NE(earlier.err.find("rig.captures already holds captures (pose00/)"), std::string::npos)
      << earlier.err;

  // The table's form: its options only with --device --turntable, no poses, no earlier views.
  EXPECT_EQ(cli({"calibrate", "--device", "127.0.0.1:1", "--views", "6", "--target", "9x6",
                 "--square", "0.03", "--out", "x.json"})
                .code,
            host::kExitUsage);
  EXPECT_EQ(cli({"calibrate", "--turntable", "--rig", rig, "--captures", "c", "--span", "60",
                 "--out", "x.json"})
                .code,
            host::kExitUsage);
  EXPECT_EQ(cli({"calibrate", "--device", "127.0.0.1:1", "--turntable", "--poses", "6", "--out",
                 "x.json"})
                .code,
            host::kExitUsage);
  EXPECT_EQ(cli({"calibrate", "--device", "127.0.0.1:1", "--turntable", "--views", "3", "--out",
                 "x.json"})
                .code,
            host::kExitUsage);
  fs::create_directories(out / "table.captures/view00");
  const auto earlierViews =
      cli({"calibrate", "--device", "127.0.0.1:1", "--turntable", "--target", "9x6", "--square",
           "0.03", "--out", (out / "table.json").string()});
  EXPECT_EQ(earlierViews.code, host::kExitUsage);
  EXPECT_NE(earlierViews.err.find("table.captures already holds captures (view00/)"),
            std::string::npos)
      << earlierViews.err;
  const auto noTable = cli({"calibrate", "--device", "127.0.0.1:1", "--turntable", "--target",
                            "9x6", "--square", "0.03", "--out", (out / "rig.json").string()});
  EXPECT_EQ(noTable.code, host::kExitDeviceOrIo) << noTable.err;
  EXPECT_FALSE(fs::exists(out / "rig.json"));
}

// `stripemux sim --calibration` scene, each pose held for `hold` frames, rendered at
// `supersampling`: fewer frames per pose and samples per pixel keep the test short; the guided
// capture needs 5 frames of a pose (two still off frames, one per projector, the off frame again).
fs::path quickCalibrationScene(const fs::path& simOut, int hold, int supersampling) {
  std::ifstream in(simOut / "truth/scene.json");
  Json scene = Json::parse(in);
  scene["supersampling"] = supersampling;
  for (auto& object : scene["objects"]) {
    if (object.contains("pose_sequence")) {
      object["pose_sequence"]["hold_frames"] = hold;
    }
  }
  const fs::path file = simOut / "truth/quick_scene.json";
  std::ofstream(file) << scene.dump(2);
  return file;
}

// Given a device playing a person placing the target in turn (a `stripemux sim --calibration`
// scene) with the true rig, announcing a rig whose proj1 is 6 mm off, `calibrate --device
// --poses 6` captures six poses into RIG.captures beside --out and solves: proj1 lands near
// where the board renders it (truth/rig.json), far nearer than the announced rig has it.
TEST(DeviceCommandsSim, GuidedCalibrateOnADeviceFindsTheRenderedRig) {
  const fs::path nominalFile = kSource / "boards/sim/rig_2proj_1cam.json";
  const fs::path sim = scratch("calibration_sim");
  const auto rendered =
      cli({"sim", "--rig", nominalFile.string(), "--calibration", "8", "--out", sim.string()});
  ASSERT_EQ(rendered.code, 0) << rendered.err;
  const algo::Rig truth = loadRig(sim / "truth/rig.json");
  const algo::Rig announced = withProjectorMoved(truth, 1, 1, 0.006);
  std::ifstream targetIn(sim / "target.json");
  const Json target = Json::parse(targetIn);
  const std::string corners = std::to_string(target["inner_corners"][0].get<int>()) + "x" +
                              std::to_string(target["inner_corners"][1].get<int>());

  const RenderingDevice device(quickCalibrationScene(sim, 6, 1).string(), truth, announced);
  const fs::path out = scratch("calibrated");
  const auto run =
      cli({"calibrate", "--device", device.address(), "--poses", "6", "--target", corners,
           "--square", std::to_string(target["square_m"].get<double>()), "--out",
           (out / "rig.json").string(), "--report", (out / "report").string()});
  ASSERT_EQ(run.code, host::kExitOk) << run.err << "\n" << run.out;

  EXPECT_NE(run.out.find("pose05: captured"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("wrote " + (out / "rig.json").string()), std::string::npos) << run.out;
  for (const char* file : {"target.json", "pose00/cam0.png", "pose05/proj1.cam0.png"}) {
    EXPECT_TRUE(fs::exists(out / "rig.captures" / file)) << file;
  }
  EXPECT_TRUE(fs::exists(out / "report/summary.txt"));

  const algo::Rig solved = loadRig(out / "rig.json");
  ASSERT_EQ(solved.projectors.size(), 2U);
  EXPECT_NEAR(solved.cameras[0].fx(), truth.cameras[0].fx(), 4.0);
  // proj1 from 6 mm off to within 1.5 mm; proj0, announced where it is, stays near. Along a
  // projector's stripes its place is seen only through the target poses, hence the looser bound.
  EXPECT_GT(distanceMm(announced.projectors[1], truth.projectors[1]), 5.9);
  EXPECT_LT(distanceMm(solved.projectors[1], truth.projectors[1]), 1.5);
  EXPECT_LT(distanceMm(solved.projectors[0], truth.projectors[0]), 3.0);
}

// Given the turntable board rendering the printed target leaning on its table (a `stripemux sim
// --table-calibration` pose at 0 deg, the table's axis where that command puts it) and announcing
// its rig without an axis, `calibrate --device --turntable --views 6` turns the table through six
// angles, captures them into RIG.captures beside --out, turns the table back and solves: the axis
// lies on the rendered one.
TEST(DeviceCommandsSim, GuidedTableCalibrateOnADeviceFindsTheTablesAxis) {
  const config::Board board = test::sourceBoard("sim-turntable");
  const fs::path sim = scratch("table_sim");
  const fs::path rigFile = kSource / "boards/sim-turntable/rig.json";
  const auto rendered =
      cli({"sim", "--rig", rigFile.string(), "--table-calibration", "5", "--out", sim.string()});
  ASSERT_EQ(rendered.code, 0) << rendered.err;
  std::ifstream axisIn(sim / "truth/axis.json");
  const Json axis = Json::parse(axisIn);
  std::ifstream sceneIn(sim / "truth/scene.json");
  Json scene = Json::parse(sceneIn);
  scene["supersampling"] = 1;
  scene["turntable"] = {{"axis", axis["direction"]}, {"pivot", axis["point"]}};
  ASSERT_EQ(scene["objects"].size(), 1U);
  Json& sheet = scene["objects"][0];
  const Json atZero = sheet["pose_sequence"]["poses"][2];  // of −40, −20, 0, 20, 40 deg
  sheet["pose_sequence"]["poses"] = Json::array({atZero});
  sheet["on_turntable"] = true;
  const fs::path sceneFile = sim / "truth/table_scene.json";
  std::ofstream(sceneFile) << scene.dump(2);
  std::ifstream targetIn(sim / "target.json");
  const Json target = Json::parse(targetIn);

  algo::Rig announced = board.rig;
  announced.turntable.reset();
  const test::SimDevice device(test::renderingScene(board, sceneFile.string(), announced),
                               {.loops = test::SimLoops::kServe, .renderedRig = board.rig});
  const fs::path out = scratch("table_calibrated");
  const auto run =
      cli({"calibrate", "--device", device.address(), "--turntable", "--views", "6", "--target",
           std::to_string(target["inner_corners"][0].get<int>()) + "x" +
               std::to_string(target["inner_corners"][1].get<int>()),
           "--square", std::to_string(target["square_m"].get<double>()), "--out",
           (out / "rig.json").string()});
  ASSERT_EQ(run.code, host::kExitOk) << run.err << "\n" << run.out;
  EXPECT_NE(run.out.find("view05: captured at 40.0 deg"), std::string::npos) << run.out;
  for (const char* file : {"target.json", "turntable.json", "view00/cam0.png", "view05/cam1.png"}) {
    EXPECT_TRUE(fs::exists(out / "rig.captures" / file)) << file;
  }
  ASSERT_NE(device.hal().turntable, nullptr);
  EXPECT_EQ(device.hal().turntable->position(), 0) << "the table is turned back";

  const algo::Rig solved = loadRig(out / "rig.json");
  ASSERT_TRUE(solved.turntable.has_value());
  const auto vec = [](const Json& v) {
    return std::array<double, 3>{v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
  };
  const std::array<double, 3> d = vec(axis["direction"]);
  const std::array<double, 3> p = vec(axis["point"]);
  const std::array<double, 3>& a = solved.turntable->axis;
  const double cosine = std::abs(a[0] * d[0] + a[1] * d[1] + a[2] * d[2]) /
                        std::hypot(a[0], a[1], a[2]) / std::hypot(d[0], d[1], d[2]);
  EXPECT_LT(std::acos(std::min(cosine, 1.0)) * 180.0 / std::numbers::pi, 0.3);
  // The solved point's distance from the rendered line.
  const std::array<double, 3> q = solved.turntable->point;
  const std::array<double, 3> e{q[0] - p[0], q[1] - p[1], q[2] - p[2]};
  const double along = (e[0] * d[0] + e[1] * d[1] + e[2] * d[2]) / std::hypot(d[0], d[1], d[2]);
  const double off =
      std::sqrt(std::max(0.0, e[0] * e[0] + e[1] * e[1] + e[2] * e[2] - along * along));
  EXPECT_LT(off, 0.002);
}

// Given a board without a turntable, `calibrate --device --turntable` says so and writes nothing.
TEST(DeviceCommandsSim, GuidedTableCalibrateRefusesADeviceWithoutATable) {
  const algo::Rig rig = loadRig(kSource / "boards/sim/rig_2proj_1cam.json");
  const RenderingDevice device("plane", rig, rig);
  const fs::path out = scratch("no_table");
  const auto run = cli({"calibrate", "--device", device.address(), "--turntable", "--target", "9x6",
                        "--square", "0.03", "--out", (out / "rig.json").string()});
  EXPECT_EQ(run.code, host::kExitBadInput) << run.err;
  EXPECT_NE(run.err.find("the device has no turntable"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(out / "rig.json"));
  EXPECT_FALSE(fs::exists(out / "rig.captures/view00"));
}

}  // namespace
}  // namespace smx
