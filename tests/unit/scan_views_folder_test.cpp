#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_harness.hpp"
#include "scan_truth_views.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/scan/views_folder.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::scan {
namespace {

namespace fs = std::filesystem;

// A `scan` folder as docs/scanning.md describes it, written with the project's own writers.
void writeFolder(const fs::path& dir, const algo::Rig& rig, const std::vector<RangeView>& views,
                 const std::vector<ViewEntry>& entries,
                 const std::optional<TurntableAxis>& axis = std::nullopt) {
  fs::create_directories(dir / "views");
  std::ofstream(dir / "rig.json") << config::toJson(rig);
  std::ofstream(dir / "views" / "views.json")
      << viewsJson(ScanMode::kTurntable, test::kDepthUnitM, entries, axis);
  for (const auto& view : views) {
    fs::create_directories(dir / "views" / view.id);
    for (std::size_t c = 0; c < view.cameras.size(); ++c) {
      const auto& range = view.cameras[c];
      ASSERT_TRUE(sim::writePngGray16(
          dir / "views" / view.id / (rig.cameras[c].id + ".depth.png"),
          *algo::ImageView<const std::uint16_t>::packed(range.depth, range.width, range.height)));
    }
  }
}

std::vector<ViewEntry> entriesOf(const std::vector<RangeView>& views) {
  std::vector<ViewEntry> entries;
  for (const auto& v : views) {
    entries.push_back({.id = v.id, .captureNs = 1000, .turntableDeg = v.turntableDeg, .pose = {}});
  }
  return entries;
}

class ScanViewsFolder : public ::smx::test::CliTest {
 protected:
  static void SetUpTestSuite() {
    rig_ = test::twoCameraRig();
    const auto scene = test::sphereScene(0.06, {0.03, 0, 0.88});
    for (int i = 0; i < 4; ++i) {
      views_.push_back(
          test::renderView(rig_, scene, test::tableAxis(), 90.0 * i, "v" + std::to_string(i)));
    }
  }
  static inline algo::Rig rig_;
  static inline std::vector<RangeView> views_;
};

TEST_F(ScanViewsFolder, ReadsBackWhatWasWritten) {
  auto entries = entriesOf(views_);
  const Pose pose = test::tableMotion(test::tableAxis(), 12);
  entries[1].pose = pose;
  writeFolder(dir_, rig_, views_, entries, test::tableAxis());
  const auto folder = readViewsFolder(dir_);
  ASSERT_TRUE(folder.has_value()) << folder.error();
  EXPECT_EQ(folder->mode, ScanMode::kTurntable);
  ASSERT_EQ(folder->views.size(), 4U);
  ASSERT_TRUE(folder->axis.has_value());
  EXPECT_LT((folder->axis->direction - test::tableAxis().direction).norm(), 1e-12);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(folder->views[i].id, views_[i].id);
    EXPECT_EQ(folder->views[i].turntableDeg, views_[i].turntableDeg);
    EXPECT_EQ(folder->views[i].cameras[1].depth, views_[i].cameras[1].depth);
  }
  ASSERT_TRUE(folder->poses[1].has_value());
  EXPECT_LT((folder->poses[1]->matrix() - pose.matrix()).norm(), 1e-12);
  EXPECT_FALSE(folder->poses[0].has_value());
}

// Hostile folders: each is refused with a message naming the file and what is wrong.
TEST_F(ScanViewsFolder, RefusesPathIdsWrongSizesMissingFilesAndBadPoses) {
  const std::vector<RangeView> one(views_.begin(), views_.begin() + 1);
  const auto refusal = [&](const std::vector<ViewEntry>& entries) {
    fs::remove_all(dir_);
    writeFolder(dir_, rig_, one, entriesOf(one));
    std::ofstream(dir_ / "views" / "views.json")
        << viewsJson(ScanMode::kTurntable, test::kDepthUnitM, entries);
    const auto folder = readViewsFolder(dir_);
    return folder ? std::string("accepted") : folder.error();
  };

  auto entries = entriesOf(one);
  entries[0].id = "../../etc";
  std::string message = refusal(entries);
  EXPECT_NE(message.find("views.json: views[0].id: a view id is a name"), std::string::npos)
      << message;

  entries = entriesOf(one);
  entries[0].id = "gone";
  message = refusal(entries);
  EXPECT_NE(message.find("views/gone/cam0.depth.png: missing"), std::string::npos) << message;

  entries = entriesOf(one);
  Eigen::Matrix4d sheared = Eigen::Matrix4d::Identity();
  sheared(0, 1) = 0.3;
  entries[0].pose = Pose(sheared);
  message = refusal(entries);
  EXPECT_NE(message.find("views[0].pose: must be a rigid motion"), std::string::npos) << message;

  // A depth image of another size than the rig's camera, refused before its pixels are read.
  fs::remove_all(dir_);
  writeFolder(dir_, rig_, one, entriesOf(one));
  const std::vector<std::uint16_t> small(32 * 24, 5000);
  ASSERT_TRUE(sim::writePngGray16(dir_ / "views" / "v0" / "cam1.depth.png",
                                  *algo::ImageView<const std::uint16_t>::packed(small, 32, 24)));
  const auto folder = readViewsFolder(dir_);
  ASSERT_FALSE(folder.has_value());
  EXPECT_NE(folder.error().find("cam1.depth.png"), std::string::npos) << folder.error();
  EXPECT_NE(folder.error().find("32"), std::string::npos) << folder.error();
  EXPECT_NE(folder.error().find("camera cam1"), std::string::npos) << folder.error();
}

TEST_F(ScanViewsFolder, ReadsAStreamFolderOfCompleteFrames) {
  std::ofstream(dir_ / "rig.json") << config::toJson(rig_);
  std::ofstream(dir_ / "summary.json") << R"({"depth_unit_m": 0.0002})";
  const auto write = [&](const std::string& name, const CameraRange& range) {
    ASSERT_TRUE(sim::writePngGray16(dir_ / name, *algo::ImageView<const std::uint16_t>::packed(
                                                     range.depth, range.width, range.height)));
  };
  write("cam0_7.depth.png", views_[0].cameras[0]);
  write("cam1_7.depth.png", views_[0].cameras[1]);
  write("cam0_8.depth.png", views_[1].cameras[0]);  // cam1 never sent frame 8
  std::ofstream(dir_ / "cam0_x.depth.png") << "not a frame";
  const auto folder = readViewsFolder(dir_);
  ASSERT_TRUE(folder.has_value()) << folder.error();
  EXPECT_EQ(folder->mode, ScanMode::kStream);
  ASSERT_EQ(folder->views.size(), 1U);
  EXPECT_EQ(folder->views[0].id, "00007");
  EXPECT_DOUBLE_EQ(folder->views[0].depthUnitM, 0.0002);
  EXPECT_EQ(folder->views[0].cameras[0].depth, views_[0].cameras[0].depth);
}

// Given a turntable folder with its axis, when fused, then every output is written and the
// report says every view was fused; given views that do not overlap, nothing is written.
TEST_F(ScanViewsFolder, FuseWritesTheModelOrNothing) {
  writeFolder(dir_, rig_, views_, entriesOf(views_), test::tableAxis());
  const auto out = dir_ / "model";
  auto run = ::smx::test::runCli({"fuse", dir_.string(), "--out", out.string(), "--voxel", "2"});
  ASSERT_EQ(run.code, 0) << run.out << run.err;
  for (const auto* name :
       {"model.ply", "mesh.ply", "mesh.obj", "mesh.stl", "report.json", "views/poses.json"}) {
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  }
  std::ifstream reportFile(out / "report.json");
  const auto report = nlohmann::json::parse(reportFile);
  EXPECT_EQ(report["views_fused"], 4);
  EXPECT_EQ(report["placement"], "turntable");
  // Binary STL: 80 + 4 + 50 bytes per triangle.
  EXPECT_EQ(fs::file_size(out / "mesh.stl"),
            84 + 50 * report["mesh"]["triangles"].get<std::size_t>());

  // The same views without the axis in the folder: --axis gives it.
  const auto noAxis = dir_ / "no_axis";
  writeFolder(noAxis, rig_, views_, entriesOf(views_));
  run = ::smx::test::runCli(
      {"fuse", noAxis.string(), "--voxel", "2", "--axis", "0,-1,0", "--axis-point", "0,0,0.9"});
  ASSERT_EQ(run.code, 0) << run.out << run.err;
  std::ifstream again(noAxis / "report.json");
  EXPECT_EQ(nlohmann::json::parse(again)["placement"], "turntable");
  EXPECT_EQ(::smx::test::runCli({"fuse", noAxis.string(), "--axis", "0,-1,0"}).code, 1);
  run = ::smx::test::runCli({"fuse", dir_.string(), "--out", (dir_ / "closed").string(), "--voxel",
                             "2", "--watertight", "--hole-max", "8"});
  ASSERT_EQ(run.code, 0) << run.out << run.err;
  std::ifstream closed(dir_ / "closed" / "report.json");
  EXPECT_EQ(nlohmann::json::parse(closed)["watertight"], true);

  // Two views of different spheres far apart, no poses, no axis.
  const auto bad = dir_ / "bad";
  auto stray = test::renderView(rig_, test::sphereScene(0.02, {-0.15, 0.1, 0.7}), test::tableAxis(),
                                0, "stray");
  std::vector<RangeView> apart = {views_[0], stray};
  auto entries = entriesOf(apart);
  for (auto& e : entries) {
    e.turntableDeg.reset();
  }
  writeFolder(bad, rig_, apart, entries);
  run = ::smx::test::runCli({"fuse", bad.string(), "--out", (dir_ / "none").string()});
  EXPECT_EQ(run.code, 2);
  EXPECT_NE(run.err.find("overlap"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir_ / "none"));
}

}  // namespace
}  // namespace smx::scan
