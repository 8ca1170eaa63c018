// config.json (docs/config.md): settings read and checked against the board, errors naming the
// key, a stored configuration merged with a change, and the board as the device runs it.
#include "smx/config/device_config.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "smx/algo/range_image.hpp"
#include "smx/config/rig_json.hpp"
#include "source_dir.hpp"

namespace smx::config {
namespace {

Board simBoard() {
  auto board = loadBoard(test::sourceDir() / "boards" / "sim");
  EXPECT_TRUE(board.has_value()) << board.error().message();
  return *board;
}

std::string doc(const std::string& body) {
  return R"({"format": "stripemux-config/1")" + (body.empty() ? "" : ", " + body) + "}";
}

TEST(DeviceConfig, ReadsEverySetting) {
  const Board board = simBoard();
  const std::string rig = toJson(board.rig);
  const auto config = parseDeviceConfig(doc(R"("fps": 12, "compression": "none", "depth_min_m": 0.3,
                                "depth_max_m": 1.5, "confidence_min": 100, "rig": )" +
                                            rig),
                                        board);
  ASSERT_TRUE(config.has_value()) << config.error().field << ": " << config.error().problem;
  EXPECT_EQ(config->fps, 12);
  EXPECT_EQ(config->compression, Compression::kNone);
  EXPECT_EQ(config->depthMinM, 0.3);
  EXPECT_EQ(config->depthMaxM, 1.5);
  EXPECT_EQ(config->confidenceMin, 100);
  ASSERT_TRUE(config->rig.has_value());
  EXPECT_EQ(config->rig->cameras[1].id, "cam1");
}

// Each bad document is refused with the field that is wrong and words that say why.
TEST(DeviceConfig, BadValuesAreRefusedNamingTheKey) {
  const Board board = simBoard();
  algo::Rig otherIds = board.rig;
  otherIds.cameras[0].id = "left";
  algo::Rig otherSize = board.rig;
  otherSize.cameras[1].width /= 2;
  otherSize.cameras[0].width /= 2;
  struct Case {
    std::string text;
    std::string field;
    std::string words;
  };
  const Case cases[] = {
      {doc(R"("fps": 0)"), "fps", "from 1 to 120"},
      {doc(R"("fps": 12.5)"), "fps", "integer"},
      {doc(R"("compression": "zip")"), "compression", "any, rvl, none"},
      {doc(R"("exposure": 3)"), "", "unknown key \"exposure\""},
      {doc(R"("depth_min_m": -1)"), "depth_min_m", "negative"},
      {doc(R"("depth_min_m": 2, "depth_max_m": 1)"), "depth_max_m", "empty"},
      {doc(R"("confidence_min": 256)"), "confidence_min", "from 1 to 255"},
      {doc(R"("exposure_us": 0)"), "exposure_us", "from 1 to 1000000"},
      {doc(R"("exposure_us": "auto")"), "exposure_us", "number"},
      {doc(R"("gain": 0.5)"), "gain", "from 1 to 64"},
      {doc(R"("gain": "camera ")"), "gain", "number"},
      {doc(R"("projectors": [])"), "projectors", "non-empty list"},
      {doc(R"("projectors": "proj0")"), "projectors", "non-empty list"},
      {doc(R"("projectors": ["proj0", "proj7"])"), "projectors[1]", "not a projector of the board"},
      {doc(R"("projectors": ["proj1", "proj1"])"), "projectors[1]", "listed twice"},
      {doc(R"("projectors": [1])"), "projectors[0]", "not a projector"},
      {doc(R"("projector_power": 0)"), "projector_power", "from 1 to 100"},
      {doc(R"("rig": 5)"), "rig", "object"},
      {doc(R"("rig": )" + toJson(otherIds)), "rig.cameras[0].id", "\"cam0\""},
      {doc(R"("rig": )" + toJson(otherSize)), "rig.cameras[0]", "the board's camera is"},
      {R"({"format": "stripemux-rig/1"})", "format", "rig.json"},
      {"{", "", "not valid JSON"},
  };
  for (const Case& c : cases) {
    const auto config = parseDeviceConfig(c.text, board);
    ASSERT_FALSE(config.has_value()) << c.text;
    EXPECT_EQ(config.error().field, c.field) << c.text;
    EXPECT_NE(config.error().problem.find(c.words), std::string::npos)
        << c.text << " -> " << config.error().problem;
  }
}

// A change that only moves the far limit is checked against the stored near one.
TEST(DeviceConfig, DepthWindowIsCheckedAgainstTheStoredSettings) {
  const Board board = simBoard();
  DeviceConfig stored;
  stored.depthMinM = 1.0;
  EXPECT_FALSE(parseDeviceConfig(doc(R"("depth_max_m": 0.8)"), board, stored).has_value());
  EXPECT_TRUE(parseDeviceConfig(doc(R"("depth_max_m": 1.2)"), board, stored).has_value());
  // The sim board stores 0.1 mm units: 6.5535 m is the farthest depth it holds.
  EXPECT_FALSE(parseDeviceConfig(doc(R"("depth_min_m": 7)"), board).has_value());
}

TEST(DeviceConfig, AChangeReplacesOnlyItsKeysAndRoundTrips) {
  const Board board = simBoard();
  const auto stored = parseDeviceConfig(doc(R"("fps": 12, "confidence_min": 50)"), board);
  const auto change = parseDeviceConfig(doc(R"("confidence_min": 80)"), board);
  ASSERT_TRUE(stored && change);
  const DeviceConfig result = merged(*stored, *change);
  EXPECT_EQ(result.fps, 12);
  EXPECT_EQ(result.confidenceMin, 80);
  EXPECT_FALSE(result.depthMaxM.has_value());
  const auto back = parseDeviceConfig(toJson(result), board);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->fps, 12);
  EXPECT_EQ(back->confidenceMin, 80);
  EXPECT_FALSE(back->compression.has_value());
}

TEST(DeviceConfig, EffectiveSettingsFillInTheBoards) {
  const Board board = simBoard();
  const auto config = parseDeviceConfig(doc(R"("depth_max_m": 2)"), board);
  ASSERT_TRUE(config.has_value());
  const auto all = parseDeviceConfig(effectiveJson(*config, board), board);
  ASSERT_TRUE(all.has_value());
  EXPECT_EQ(all->fps, 30);  // boards/sim/board.json
  EXPECT_EQ(all->compression, Compression::kAny);
  EXPECT_EQ(all->depthMinM, 0.0);
  EXPECT_EQ(all->depthMaxM, 2.0);
  const auto none = parseDeviceConfig(effectiveJson({}, board), board);
  ASSERT_TRUE(none.has_value());
  EXPECT_EQ(none->depthMaxM, 6.5535);  // 65535 units of 0.1 mm
  EXPECT_EQ(all->confidenceMin, 1);
  ASSERT_TRUE(all->rig.has_value());
  EXPECT_EQ(toJson(*all->rig), toJson(board.rig));
}

TEST(DeviceConfig, AppliedToTheBoardSetsFrameRateAndRig) {
  const Board board = simBoard();
  algo::Rig moved = board.rig;
  moved.projectors[0].t[0] += 0.01;
  DeviceConfig config;
  config.fps = 7;
  config.rig = moved;
  const Board applied = appliedTo(config, board);
  for (const auto& camera : applied.config.cameras) {
    EXPECT_EQ(camera.format.fps, 7);
  }
  EXPECT_EQ(applied.rig.projectors[0].t[0], moved.projectors[0].t[0]);
  EXPECT_EQ(applied.config.name, board.config.name);
}

TEST(DeviceConfig, CameraAndProjectorSettings) {
  const Board board = simBoard();
  const auto config = parseDeviceConfig(
      doc(R"("exposure_us": 20000, "gain": 2.5, "projectors": ["proj1"], "projector_power": 40)"),
      board);
  ASSERT_TRUE(config.has_value()) << config.error().field << ": " << config.error().problem;
  const Board applied = appliedTo(*config, board);
  for (const auto& camera : applied.config.cameras) {
    EXPECT_EQ(camera.controls.exposureUs, 20000);
    EXPECT_EQ(camera.controls.gain, 2.5);
  }
  EXPECT_EQ(applied.config.trigger.powerPercent, 40);
  // boards/sim: proj0 is line 0, proj1 line 1.
  EXPECT_EQ(rangeProjectorsMask(applied), 0b10U);
  const algo::Rig rig = rangeRig(applied);
  ASSERT_EQ(rig.projectors.size(), 1U);
  EXPECT_EQ(rig.projectors[0].id, "proj1");
  EXPECT_EQ(rig.cameras.size(), board.rig.cameras.size());

  // Listed in any order, kept in the rig's; "camera" goes back to the camera's own.
  const auto reordered =
      parseDeviceConfig(doc(R"("projectors": ["proj1", "proj0"], "exposure_us": "camera")"), board);
  ASSERT_TRUE(reordered.has_value());
  EXPECT_EQ(*reordered->projectors, (std::vector<std::string>{"proj0", "proj1"}));
  const Board back = appliedTo(merged(*config, *reordered), board);
  EXPECT_FALSE(back.config.cameras[0].controls.exposureUs.has_value());
  EXPECT_EQ(back.config.cameras[0].controls.gain, 2.5);
  EXPECT_EQ(rangeProjectorsMask(back), 0b11U);
  const auto again = parseDeviceConfig(toJson(merged(*config, *reordered)), board);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->exposureUs, 0);
}

TEST(DeviceConfig, WithoutSettingsEveryProjectorIsLitAtFullPower) {
  const Board board = simBoard();
  const Board applied = appliedTo({}, board);
  EXPECT_EQ(rangeProjectorsMask(applied), 0b11U);
  EXPECT_EQ(applied.config.trigger.powerPercent, 100);
  EXPECT_FALSE(applied.config.cameras[0].controls.exposureUs.has_value());
  const auto all = parseDeviceConfig(effectiveJson({}, board), board);
  ASSERT_TRUE(all.has_value());
  EXPECT_EQ(*all->projectors, (std::vector<std::string>{"proj0", "proj1"}));
  EXPECT_EQ(all->projectorPower, 100);
  EXPECT_EQ(all->exposureUs, 0);  // "camera"
}

}  // namespace
}  // namespace smx::config
