#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "cli.hpp"
#include "cli_harness.hpp"
#include "pattern_sampler.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/sim/png_io.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

using test::CliRun;

CliRun run(const std::vector<std::string>& args) {
  return test::runCli(args);
}

class CliPattern : public test::CliTest {};

const std::string kExampleRigs[] = {"rig_2proj_1cam.json", "rig_2proj_2cam.json",
                                    "rig_3proj_1cam.json", "rig_3proj_2cam.json"};

// Given each example rig, when `stripemux pattern` runs, then every projector gets a PNG of its
// size in which the stripe sequence is found along that projector's axis.
TEST_F(CliPattern, WritesEachProjectorsPatternRecoverableAlongItsAxis) {
  for (const auto& name : kExampleRigs) {
    const fs::path rigPath = smx::test::sourceDir() / "boards/sim" / name;
    const auto out = dir_ / name;
    const auto result = run({"pattern", "--rig", rigPath.string(), "--out", out.string()});
    ASSERT_EQ(result.code, kExitOk) << result.err;
    const auto rig = config::loadRig(rigPath);
    ASSERT_TRUE(rig.has_value());
    for (const auto& projector : rig->projectors) {
      const auto image = sim::readPngRgb8(out / (projector.id + ".png"));
      ASSERT_TRUE(image.has_value()) << image.error();
      EXPECT_EQ(image->width, projector.width);
      EXPECT_EQ(image->height, projector.height);
      const auto sampled = test::sampleAlongAxis(image->view(), projector.pattern);
      ASSERT_TRUE(sampled.has_value()) << name << " " << projector.id;
      EXPECT_GE(sampled->size(), 100U) << name << " " << projector.id;
      for (const auto& s : *sampled) {
        ASSERT_EQ(s.colour, algo::stripe::kSequence[static_cast<std::size_t>(s.index)])
            << name << " " << projector.id << " stripe " << s.index;
      }
      EXPECT_NE(result.out.find(projector.id + ".png"), std::string::npos);
    }
  }
}

TEST_F(CliPattern, BadRigIsRejectedWithFileAndFieldAndNothingWritten) {
  const auto rigPath = writeFile("bad.json", R"({"format": "stripemux-rig/1",
    "cameras": [{"id": "cam0", "width": 640, "height": 480,
                 "K": [800,0,319.5, 0,800,239.5, 0,0,1], "dist": [0,0,0,0,0],
                 "R": [1,0,0, 0,1,0, 0,0,1], "t": [0,0,0]}],
    "projectors": [{"id": "proj0", "width": 1024, "height": 768,
                    "K": [1400,0,511.5, 0,1400,383.5, 0,0,1], "dist": [0,0,0,0,0],
                    "R": [1,0,0, 0,1,0, 0,0,1], "t": [0.3,0,0],
                    "pattern": {"angle_deg": 0, "stripe_px": -5, "offset_px": 0}}]})");
  const auto out = dir_ / "out";
  const auto result = run({"pattern", "--rig", rigPath.string(), "--out", out.string()});
  EXPECT_EQ(result.code, kExitBadInput);
  EXPECT_NE(result.err.find("bad.json"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("projectors[0].pattern.stripe_px"), std::string::npos) << result.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(CliPattern, MissingOrMalformedRigFileIsBadInput) {
  const auto missing =
      run({"pattern", "--rig", (dir_ / "nope.json").string(), "--out", (dir_ / "o").string()});
  EXPECT_EQ(missing.code, kExitBadInput);
  EXPECT_NE(missing.err.find("nope.json"), std::string::npos) << missing.err;

  const auto malformed = writeFile("malformed.json", "{\"format\": \"stripemux-rig/1\",");
  const auto result = run({"pattern", "--rig", malformed.string(), "--out", (dir_ / "o").string()});
  EXPECT_EQ(result.code, kExitBadInput);
  EXPECT_NE(result.err.find("malformed.json"), std::string::npos) << result.err;
}

TEST_F(CliPattern, UnwritableOutputIsAnIoError) {
  const auto blocker = writeFile("file", "not a directory");
  const fs::path rigPath = smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json";
  const auto result =
      run({"pattern", "--rig", rigPath.string(), "--out", (blocker / "sub").string()});
  EXPECT_EQ(result.code, kExitDeviceOrIo);
  EXPECT_NE(result.err.find("sub"), std::string::npos) << result.err;
}

TEST_F(CliPattern, UsageErrorsExitOne) {
  EXPECT_EQ(run({"pattern", "--out", "x"}).code, kExitUsage);  // --rig missing
  EXPECT_EQ(run({"frobnicate"}).code, kExitUsage);
  EXPECT_EQ(run({"pattern", "--rig", "a", "--out", "b", "--bogus"}).code, kExitUsage);
}

TEST_F(CliPattern, NoArgumentsPrintsHelpAndHelpExitsZero) {
  const auto none = run({});
  EXPECT_EQ(none.code, kExitOk);
  EXPECT_NE(none.out.find("pattern"), std::string::npos);
  const auto help = run({"pattern", "--help"});
  EXPECT_EQ(help.code, kExitOk);
  EXPECT_NE(help.out.find("--rig"), std::string::npos);
}

}  // namespace
}  // namespace smx::host
