// The turntable's axis from rendered captures of the target leaning on a table
// (`stripemux sim --table-calibration`, then calib::calibrateTable): the fitted line against the
// line the simulator turned the target about, and the capture sets it must refuse.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "cli_harness.hpp"
#include "smx/calib/table_captures.hpp"
#include "smx/config/rig_json.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

const fs::path kRig = smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json";
constexpr int kViews = 6;

// One rendered set per run, shared by the tests.
const fs::path& captures() {
  static const fs::path dir = [] {
    const fs::path d =
        fs::temp_directory_path() / ("smx_table_captures_" + std::to_string(getpid()));
    fs::remove_all(d);
    const auto run = test::runCli({"sim", "--rig", kRig.string(), "--table-calibration",
                                   std::to_string(kViews), "--out", d.string()});
    EXPECT_EQ(run.code, 0) << run.err;
    return d;
  }();
  return dir;
}

Eigen::Vector3d vec(const nlohmann::json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

class TableCaptures : public ::testing::Test {
 protected:
  static void TearDownTestSuite() { fs::remove_all(captures()); }
};

TEST_F(TableCaptures, TheFittedAxisIsTheLineTheTargetTurnedAbout) {
  const auto rig = config::loadRig(kRig);
  ASSERT_TRUE(rig);
  const auto fit = calib::calibrateTable(*rig, captures());
  ASSERT_TRUE(fit) << fit.error();
  std::ifstream in(captures() / "truth/axis.json");
  const auto truth = nlohmann::json::parse(in);
  const Eigen::Vector3d direction = vec(truth.at("direction")).normalized();
  const Eigen::Vector3d point = vec(truth.at("point"));
  const double angleDeg =
      std::acos(std::min(1.0, fit->axis.direction.dot(direction))) * 180.0 / std::numbers::pi;
  EXPECT_LT(angleDeg, 0.2);
  EXPECT_LT((fit->axis.point - point).cross(direction).norm(), 0.002);  // on the true line
  EXPECT_NEAR(fit->axis.angleScale, 1.0, 0.01);
  EXPECT_LT(fit->axis.cornerRmsM, 0.001);
  ASSERT_EQ(fit->views.size(), static_cast<std::size_t>(kViews));
  for (const auto& view : fit->views) {
    EXPECT_EQ(view.camera, "cam0") << view.id << ": " << view.note;
  }
}

TEST_F(TableCaptures, HostileOrShortListsAreRefusedNamingTheField) {
  const auto rig = config::loadRig(kRig);
  ASSERT_TRUE(rig);
  const fs::path bad = captures().parent_path() / (captures().filename().string() + "_bad");
  fs::remove_all(bad);
  fs::copy(captures(), bad, fs::copy_options::recursive);
  const auto refusal = [&](const std::string& list) {
    writeText(bad / "turntable.json", list);
    const auto fit = calib::calibrateTable(*rig, bad);
    return fit ? std::string("(accepted)") : fit.error();
  };
  EXPECT_NE(refusal(R"({"format": "stripemux-table-captures/1", "views": [{"id": "../view00",)"
                    R"( "angle_deg": 0}]})")
                .find("views[0].id"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"format": "stripemux-table-captures/1", "views": [{"id": "view00"}]})")
                .find("views[0].angle_deg"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"format": "stripemux-table-captures/1", "views": [{"id": "view00",)"
                    R"( "angle_deg": 0}, {"id": "view00", "angle_deg": 10}]})")
                .find("listed twice"),
            std::string::npos);
  // Three views found: too few for an axis, and the message says so.
  EXPECT_NE(refusal(R"({"format": "stripemux-table-captures/1", "views": [)"
                    R"({"id": "view00", "angle_deg": -40}, {"id": "view01", "angle_deg": -24},)"
                    R"({"id": "view02", "angle_deg": -8}]})")
                .find("at least 4 are needed"),
            std::string::npos);
  // A view whose angle is wrong by 10°: the target seems to slide off the table's axis.
  std::ifstream in(captures() / "turntable.json");
  auto list = nlohmann::json::parse(in);
  list["views"][3]["angle_deg"] = list["views"][3]["angle_deg"].get<double>() + 10.0;
  const std::string wrong = refusal(list.dump());
  EXPECT_NE(wrong.find("view03"), std::string::npos) << wrong;
  fs::remove_all(bad);
}

TEST_F(TableCaptures, CalibrateWritesTheRigWithTheAxisAndNothingOnFailure) {
  const fs::path out = captures().parent_path() / (captures().filename().string() + "_out");
  fs::remove_all(out);
  fs::create_directories(out);
  const fs::path rigFile = out / "rig.json";
  const auto run = test::runCli({"calibrate", "--turntable", "--rig", kRig.string(), "--captures",
                                 captures().string(), "--out", rigFile.string()});
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("turntable axis: direction"), std::string::npos) << run.out;
  const auto rig = config::loadRig(rigFile);
  ASSERT_TRUE(rig) << rig.error().message();
  ASSERT_TRUE(rig->turntable);
  std::ifstream in(captures() / "truth/axis.json");
  const auto truth = nlohmann::json::parse(in);
  const Eigen::Vector3d direction = vec(truth.at("direction")).normalized();
  const Eigen::Vector3d written(rig->turntable->axis[0], rig->turntable->axis[1],
                                rig->turntable->axis[2]);
  EXPECT_GT(written.dot(direction), std::cos(0.2 * std::numbers::pi / 180.0));
  const Eigen::Vector3d point(rig->turntable->point[0], rig->turntable->point[1],
                              rig->turntable->point[2]);
  EXPECT_LT((point - vec(truth.at("point"))).cross(direction).norm(), 0.002);

  // Captures without a usable list: exit 2, the earlier rig.json untouched.
  const std::string before = config::toJson(*rig);
  const fs::path empty = out / "empty";
  fs::create_directories(empty);
  fs::copy_file(captures() / "target.json", empty / "target.json");
  const auto bad = test::runCli({"calibrate", "--turntable", "--rig", kRig.string(), "--captures",
                                 empty.string(), "--out", rigFile.string()});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("turntable.json"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("nothing written"), std::string::npos) << bad.err;
  const auto after = config::loadRig(rigFile);
  ASSERT_TRUE(after);
  EXPECT_EQ(config::toJson(*after), before);
  fs::remove_all(out);
}

}  // namespace
}  // namespace smx::host
