// `stripemux config` without a device (docs/config.md): what is wrong with the command line is
// said before any connection, and every shipped preset is a configuration a board accepts.
#include <gtest/gtest.h>

#include <string>

#include "cli_harness.hpp"
#include "config_presets.hpp"
#include "smx/config/device_config.hpp"
#include "source_dir.hpp"

namespace smx {
namespace {

using test::runCli;

// Port 9 (discard) on loopback: nothing listens, so a run that got as far as connecting would
// fail with exit 3, not with the usage error expected.
constexpr const char* kNoDevice = "127.0.0.1:9";

TEST(CliConfig, CommandLineMistakesAreUsageErrorsBeforeConnecting) {
  const auto unknownKey = runCli({"config", "--device", kNoDevice, "set", "exposure=3"});
  EXPECT_EQ(unknownKey.code, 1);
  EXPECT_NE(unknownKey.err.find("no setting \"exposure\"; settings: fps, exposure_us, gain"),
            std::string::npos)
      << unknownKey.err;
  const auto noValue = runCli({"config", "--device", kNoDevice, "set", "fps"});
  EXPECT_EQ(noValue.code, 1);
  EXPECT_NE(noValue.err.find("expected KEY=VALUE"), std::string::npos) << noValue.err;
  const auto noPreset = runCli({"config", "--device", kNoDevice, "apply", "fastest"});
  EXPECT_EQ(noPreset.code, 1);
  EXPECT_NE(noPreset.err.find(
                "no preset \"fastest\" (presets: fast, accurate, close-range, dark-objects"),
            std::string::npos)
      << noPreset.err;
  const auto getUnknown = runCli({"config", "--device", kNoDevice, "get", "brightness"});
  EXPECT_EQ(getUnknown.code, 1);
  const auto noDevice = runCli({"config", "get"});
  EXPECT_EQ(noDevice.code, 1);
  EXPECT_NE(noDevice.err.find("--device"), std::string::npos) << noDevice.err;
  const auto badAddress = runCli({"config", "--device", "host:99999", "get"});
  EXPECT_EQ(badAddress.code, 1);
  // A well-formed request to nobody is a device error.
  EXPECT_EQ(runCli({"config", "--device", kNoDevice, "get"}).code, 3);
}

TEST(CliConfig, AMissingOrOversizedFileIsRejectedInput) {
  const auto missing = runCli({"config", "--device", kNoDevice, "apply", "/nonexistent.json"});
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("/nonexistent.json"), std::string::npos) << missing.err;
  const auto rigMissing = runCli({"config", "--device", kNoDevice, "set", "rig=/nonexistent.json"});
  EXPECT_EQ(rigMissing.code, 2);
}

TEST(CliConfig, EveryPresetIsAConfigurationTheSimBoardAccepts) {
  const auto board = config::loadBoard(test::sourceDir() / "boards" / "sim");
  ASSERT_TRUE(board.has_value());
  const auto list = runCli({"config", "presets"});
  EXPECT_EQ(list.code, 0);
  for (const host::ConfigPreset& preset : host::configPresets()) {
    const auto parsed = config::parseDeviceConfig(preset.json, *board);
    EXPECT_TRUE(parsed.has_value())
        << preset.name << ": " << parsed.error().field << ": " << parsed.error().problem;
    EXPECT_NE(list.out.find(std::string(preset.name) + ": "), std::string::npos);
  }
}

}  // namespace
}  // namespace smx
