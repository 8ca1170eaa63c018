// `stripemux check`: a rendered frame checked with the rig it was rendered with and with one
// projector's calibration moved by 1 mm; bad input rejected by name.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli.hpp"
#include "cli_harness.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

const fs::path kRig = smx::test::sourceDir() / "boards/sim/rig_3proj_1cam.json";

class CliCheck : public test::CliTest {
 protected:
  fs::path frame() {
    const auto out = dir_ / "frame";
    const auto sim = test::runCli(
        {"sim", "--rig", kRig.string(), "--scene", "plane", "--out", out.string(), "--no-truth"});
    EXPECT_EQ(sim.code, kExitOk) << sim.err;
    return out;
  }
};

TEST_F(CliCheck, CorrectRigIsGood) {
  const auto images = frame();
  const auto run = test::runCli({"check", "--rig", kRig.string(), "--images", images.string(),
                                 "--report", (dir_ / "report").string()});
  EXPECT_EQ(run.code, kExitOk) << run.err;
  EXPECT_NE(run.out.find("good: all 3 projectors agree"), std::string::npos) << run.out;
  std::ifstream in(dir_ / "report/check.json");
  const auto json = nlohmann::json::parse(in);
  EXPECT_EQ(json["format"], "stripemux-check/1");
  EXPECT_TRUE(json["healthy"].get<bool>());
  EXPECT_EQ(json["projectors"].size(), 3U);
  EXPECT_EQ(json["comparisons"].size(), 3U);  // three projector pairs on one camera
}

// proj0's x position in the rig file 1 mm off (along its encoding axis): it is named.
TEST_F(CliCheck, MovedProjectorIsNamed) {
  const auto images = frame();
  const auto rig =
      writeFile("moved.json", test::textWith(kRig, "-0.3196959845612154", "-0.3206959845612154"));
  const auto run =
      test::runCli({"check", "--rig", rig.string(), "--images", images.string(), "--json"});
  EXPECT_EQ(run.code, 4) << run.err;
  const auto json = nlohmann::json::parse(run.out);
  EXPECT_FALSE(json["healthy"].get<bool>());
  EXPECT_EQ(json["projectors"][0]["verdict"], "drifted");
  EXPECT_EQ(json["projectors"][1]["verdict"], "good");
  EXPECT_EQ(json["projectors"][2]["verdict"], "good");
  EXPECT_EQ(json["summary"], "drifted: proj0 (recalibrate)");
}

TEST_F(CliCheck, FolderWithoutCameraImagesIsRejectedByName) {
  const auto run =
      test::runCli({"check", "--rig", kRig.string(), "--images", (dir_ / "nothing").string()});
  EXPECT_EQ(run.code, kExitBadInput);
  EXPECT_NE(run.err.find("nothing: no camera image (expected cam0.png"), std::string::npos)
      << run.err;
}

}  // namespace
}  // namespace smx::host
