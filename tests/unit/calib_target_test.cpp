// target.json and the capture folder's checks: what `stripemux calibrate` refuses before solving.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "smx/calib/capture_set.hpp"
#include "smx/calib/target.hpp"

namespace smx::calib {
namespace {

namespace fs = std::filesystem;

std::string target(const std::string& body) {
  return R"({"format": "stripemux-target/1", )" + body + "}";
}

TEST(CalibTarget, ReadsACheckerboard) {
  const auto t =
      parseTarget(target(R"("type": "checkerboard", "inner_corners": [9, 6], "square_m": 0.025)"));
  ASSERT_TRUE(t) << t.error();
  EXPECT_EQ(t->cols, 9);
  EXPECT_EQ(t->rows, 6);
  EXPECT_DOUBLE_EQ(t->squareM, 0.025);
  const auto corners = innerCorners(*t);
  ASSERT_EQ(corners.size(), 54U);
  // Row by row, x fastest, one square apart.
  EXPECT_DOUBLE_EQ(corners[1].x, 0.025);
  EXPECT_DOUBLE_EQ(corners[1].y, 0.0);
  EXPECT_DOUBLE_EQ(corners[9].x, 0.0);
  EXPECT_DOUBLE_EQ(corners[9].y, 0.025);
}

TEST(CalibTarget, RefusesWhatCannotBeDetectedOrNamed) {
  const struct {
    std::string body;
    std::string field;
  } cases[] = {
      {R"("type": "charuco", "inner_corners": [9, 6], "square_m": 0.025)", "type"},
      {R"("type": "checkerboard", "square_m": 0.025)", "inner_corners"},
      {R"("type": "checkerboard", "inner_corners": [9], "square_m": 0.025)", "inner_corners"},
      {R"("type": "checkerboard", "inner_corners": [9.5, 6], "square_m": 0.025)",
       "inner_corners[0]"},
      {R"("type": "checkerboard", "inner_corners": [2, 5], "square_m": 0.025)", "inner_corners[0]"},
      {R"("type": "checkerboard", "inner_corners": [8, 6], "square_m": 0.025)", "inner_corners"},
      {R"("type": "checkerboard", "inner_corners": [9, 6])", "square_m"},
      {R"("type": "checkerboard", "inner_corners": [9, 6], "square_m": 25)", "square_m"},
      {R"("type": "checkerboard", "inner_corners": [9, 6], "square_m": 0.02, "x": 1)", "x"},
  };
  for (const auto& c : cases) {
    const auto t = parseTarget(target(c.body));
    ASSERT_FALSE(t) << c.body;
    EXPECT_NE(t.error().find(c.field), std::string::npos) << t.error();
  }
  EXPECT_FALSE(parseTarget(R"({"format": "stripemux-rig/1"})"));
  EXPECT_FALSE(parseTarget("[["));
}

class CalibCaptureSet : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("smx_calib_set_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    rig_.cameras.resize(1);
    rig_.cameras[0].id = "cam0";
    rig_.projectors.resize(1);
    rig_.projectors[0].id = "proj0";
  }
  void TearDown() override { fs::remove_all(dir_); }
  void touch(const fs::path& file) {
    fs::create_directories(file.parent_path());
    std::ofstream(file) << "x";
  }

  fs::path dir_;
  algo::Rig rig_;
};

TEST_F(CalibCaptureSet, NamesMissingFilesAndIgnoresOtherFolders) {
  std::ofstream(dir_ / "target.json")
      << target(R"("type": "checkerboard", "inner_corners": [9, 6], "square_m": 0.025)");
  touch(dir_ / "pose00" / "cam0.png");
  touch(dir_ / "pose00" / "proj0.cam0.png");
  touch(dir_ / "pose01" / "cam0.png");
  touch(dir_ / "pose7" / "cam0.png");      // not a pose name
  touch(dir_ / "../pose02" / "cam0.png");  // outside the folder
  touch(dir_ / "notes" / "pose03.png");
  const auto set = openCaptureSet(dir_, rig_);
  ASSERT_TRUE(set) << set.error();
  ASSERT_EQ(set->poses.size(), 2U);
  EXPECT_EQ(set->poses[0].name, "pose00");
  EXPECT_FALSE(set->poses[0].lit[0][0].empty());
  EXPECT_TRUE(set->poses[1].lit[0][0].empty());
  ASSERT_EQ(set->notes.size(), 1U);
  EXPECT_NE(set->notes[0].find("pose01"), std::string::npos);
  EXPECT_NE(set->notes[0].find("proj0"), std::string::npos);
  fs::remove_all(dir_ / "../pose02");
}

TEST_F(CalibCaptureSet, RefusesAFolderWithoutTargetOrPoses) {
  auto set = openCaptureSet(dir_, rig_);
  ASSERT_FALSE(set);
  EXPECT_NE(set.error().find("target.json"), std::string::npos);
  std::ofstream(dir_ / "target.json")
      << target(R"("type": "checkerboard", "inner_corners": [9, 6], "square_m": 0.025)");
  set = openCaptureSet(dir_, rig_);
  ASSERT_FALSE(set);
  EXPECT_NE(set.error().find("no pose folders"), std::string::npos);
  set = openCaptureSet(dir_ / "missing", rig_);
  ASSERT_FALSE(set);
}

}  // namespace
}  // namespace smx::calib
