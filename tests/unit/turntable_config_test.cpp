// The turntable's configuration (board.json, rig.json) and the angle/step arithmetic its
// backends share, against values worked out by hand.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "smx/config/board_json.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/hal/turntable_motion.hpp"
#include "source_dir.hpp"

namespace smx::config {
namespace {

const std::filesystem::path kBoard = smx::test::sourceDir() / "boards" / "sim-turntable";

std::string boardText() {
  std::ifstream in(kBoard / "board.json");
  return {(std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()};
}

// The turntable board's text with its turntable section replaced by `table` (JSON object text).
std::expected<Board, BoardError> withTurntable(const std::string& table) {
  std::string text = boardText();
  const auto from = text.find(R"("turntable": {)");
  const auto to = text.find('}', from);
  EXPECT_NE(from, std::string::npos);
  text.replace(from, to + 1 - from, R"("turntable": )" + table);
  return parseBoard(text, kBoard);
}

void expectError(const std::expected<Board, BoardError>& board, const std::string& field,
                 const std::string& problemPart) {
  ASSERT_FALSE(board.has_value());
  EXPECT_EQ(board.error().field, field) << board.error().message();
  EXPECT_NE(board.error().problem.find(problemPart), std::string::npos) << board.error().message();
}

TEST(TurntableConfig, TheTurntableBoardLoadsWithItsTableAndAxis) {
  const auto board = loadBoard(kBoard);
  ASSERT_TRUE(board.has_value()) << board.error().message();
  ASSERT_TRUE(board->config.turntable.has_value());
  const hal::TurntableConfig& t = *board->config.turntable;
  EXPECT_EQ(t.stepLine, 2U);
  EXPECT_EQ(t.dirLine, 3U);
  EXPECT_EQ(t.enableLine, 4U);
  EXPECT_EQ(t.stepsPerTurn, 3200);
  EXPECT_EQ(t.speedDegS, 180.0);
  EXPECT_EQ(t.settleMs, 100);
  ASSERT_TRUE(board->rig.turntable.has_value());
  EXPECT_EQ(board->rig.turntable->axis, (std::array<double, 3>{0, -1, 0}));
  EXPECT_EQ(board->rig.turntable->point, (std::array<double, 3>{0, 0, 0.9}));

  const auto plain = loadBoard(smx::test::sourceDir() / "boards" / "sim");
  ASSERT_TRUE(plain.has_value());
  EXPECT_FALSE(plain->config.turntable.has_value());
  EXPECT_FALSE(plain->rig.turntable.has_value());
}

TEST(TurntableConfig, EachBadFieldIsNamed) {
  const std::string ok = R"("chip": "sim", "step": 2, "dir": 3)";
  EXPECT_TRUE(withTurntable("{" + ok + R"(, "steps_per_turn": 200})").has_value());
  expectError(withTurntable(R"({"chip": "sim", "dir": 3, "steps_per_turn": 200})"),
              "turntable.step", "required field is missing");
  expectError(withTurntable(R"({"chip": "sim", "step": 2, "steps_per_turn": 200})"),
              "turntable.dir", "required field is missing");
  expectError(withTurntable(R"({"step": 2, "dir": 3, "steps_per_turn": 200})"), "turntable.chip",
              "required field is missing");
  expectError(withTurntable("{" + ok + "}"), "turntable.steps_per_turn",
              "required field is missing");
  expectError(withTurntable("{" + ok + R"(, "steps_per_turn": 0})"), "turntable.steps_per_turn",
              "from 1 to 1000000");
  expectError(withTurntable("{" + ok + R"(, "steps_per_turn": 1000001})"),
              "turntable.steps_per_turn", "from 1 to 1000000");
  expectError(withTurntable("{" + ok + R"(, "steps_per_turn": 200, "speed_deg_s": 0.5})"),
              "turntable.speed_deg_s", "from 1 to 360");
  expectError(withTurntable("{" + ok + R"(, "steps_per_turn": 200, "speed_deg_s": 361})"),
              "turntable.speed_deg_s", "from 1 to 360");
  expectError(withTurntable("{" + ok + R"(, "steps_per_turn": 200, "settle_ms": 10001})"),
              "turntable.settle_ms", "from 0 to 10000");
  expectError(withTurntable("{" + ok + R"(, "steps_per_turn": 200, "settle_ms": -1})"),
              "turntable.settle_ms", "from 0 to 10000");
  expectError(withTurntable(R"({"chip": "sim", "step": 2, "dir": 2, "steps_per_turn": 200})"),
              "turntable.dir", "already the STEP line");
  expectError(withTurntable("{" + ok + R"(, "enable": 3, "steps_per_turn": 200})"),
              "turntable.enable", "already the DIR line");
  // The trigger lines are lines 0 and 1 of chip "sim".
  expectError(withTurntable(R"({"chip": "sim", "step": 1, "dir": 3, "steps_per_turn": 200})"),
              "turntable.step", "already the trigger line of \"proj1\"");
  EXPECT_TRUE(withTurntable(R"({"chip": "other", "step": 1, "dir": 3, "steps_per_turn": 200})")
                  .has_value());
  expectError(withTurntable("{" + ok + R"(, "steps_per_turn": 200, "speed": 10})"), "turntable",
              "speed");
  expectError(withTurntable("{" + ok + R"(, "steps_per_turn": 200, "enable_active_low": 1})"),
              "turntable.enable_active_low", "true or false");
}

std::string rigWithTurntable(const std::string& table) {
  std::ifstream in(kBoard / "rig.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto from = text.find(R"("turntable": {)");
  const auto to = text.find('}', from);
  text.replace(from, to + 1 - from, R"("turntable": )" + table);
  return text;
}

TEST(TurntableConfig, TheRigsAxisIsNormalisedAndCheckedAndWrittenBack) {
  const auto rig = parseRig(rigWithTurntable(R"({"axis": [0, -2, 0], "point": [0.1, 0, 1]})"));
  ASSERT_TRUE(rig.has_value()) << rig.error().message();
  EXPECT_EQ(rig->turntable->axis, (std::array<double, 3>{0, -1, 0}));
  const auto again = parseRig(toJson(*rig));
  ASSERT_TRUE(again.has_value()) << again.error().message();
  EXPECT_EQ(again->turntable->axis, rig->turntable->axis);
  EXPECT_EQ(again->turntable->point, (std::array<double, 3>{0.1, 0, 1}));

  const auto zero = parseRig(rigWithTurntable(R"({"axis": [0, 0, 0], "point": [0, 0, 1]})"));
  ASSERT_FALSE(zero.has_value());
  EXPECT_EQ(zero.error().field, "turntable.axis");
  const auto huge = parseRig(rigWithTurntable(R"({"axis": [0, 1, 0], "point": [0, 0, 1e300]})"));
  ASSERT_FALSE(huge.has_value());
  EXPECT_EQ(huge.error().field, "turntable.point[2]");
  const auto missing = parseRig(rigWithTurntable(R"({"axis": [0, 1, 0]})"));
  ASSERT_FALSE(missing.has_value());
  EXPECT_EQ(missing.error().field, "turntable.point");
  const auto nan = parseRig(rigWithTurntable(R"({"axis": [0, 1, "x"], "point": [0, 0, 1]})"));
  ASSERT_FALSE(nan.has_value());
  EXPECT_EQ(nan.error().field, "turntable.axis[2]");

  algo::Rig inMemory = *rig;
  inMemory.turntable->axis = {std::numeric_limits<double>::infinity(), 0, 0};
  const auto refused = validateRig(inMemory);
  ASSERT_FALSE(refused.has_value());
  EXPECT_EQ(refused.error().field, "turntable.axis[0]");
}

}  // namespace
}  // namespace smx::config

namespace smx::hal {
namespace {

TEST(TurntableMotion, AnglesAndStepsRoundHalfAwayFromZero) {
  // 200 steps per turn: 1.8 degrees = 1'800'000 micro-degrees a step.
  EXPECT_EQ(angleMicroDeg(1, 200), 1'800'000);
  EXPECT_EQ(angleMicroDeg(-50, 200), -90'000'000);
  // 7 steps per turn: 360e6 / 7 = 51'428'571.43 -> 51'428'571; 3 steps 154'285'714.29.
  EXPECT_EQ(angleMicroDeg(1, 7), 51'428'571);
  EXPECT_EQ(angleMicroDeg(-3, 7), -154'285'714);
  // 4 * 360e6 / 7 = 205'714'285.71 -> 205'714'286.
  EXPECT_EQ(angleMicroDeg(4, 7), 205'714'286);
  EXPECT_EQ(angleMicroDeg(std::numeric_limits<std::int64_t>::max(), 1),
            std::numeric_limits<std::int64_t>::max());

  EXPECT_EQ(stepsForAngle(90'000'000, 3200), 800);
  EXPECT_EQ(stepsForAngle(-90'000'000, 3200), -800);
  // Half a step (0.9 degrees at 200 per turn) rounds away from zero, just below it towards.
  EXPECT_EQ(stepsForAngle(900'000, 200), 1);
  EXPECT_EQ(stepsForAngle(-900'000, 200), -1);
  EXPECT_EQ(stepsForAngle(899'999, 200), 0);
  EXPECT_EQ(stepsForAngle(1, 0), std::nullopt);

  // From step 800 (90 degrees) to 45 degrees is 400 steps back; by 45 degrees 400 on.
  EXPECT_EQ(stepsToMove(800, 3200, true, 45'000'000), -400);
  EXPECT_EQ(stepsToMove(800, 3200, false, 45'000'000), 400);
  // 2^31 steps do not fit one move.
  EXPECT_EQ(stepsToMove(0, 1'000'000, false, std::int64_t{360'000'000} * 2148), std::nullopt);
  EXPECT_EQ(stepsToMove(0, 1'000'000, false, std::int64_t{360'000'000} * 2147), 2'147'000'000);
}

TEST(TurntableMotion, ThePulseScheduleFollowsTheSpeed) {
  // 3200 steps per turn at 180 deg/s: 1600 steps/s, 625 us a step.
  EXPECT_EQ(stepPeriodNs(180.0, 3200), 625'000);
  // 1'000'000 steps per turn at 360 deg/s would be 1 us: held at twice the pulse's high time.
  EXPECT_EQ(stepPeriodNs(360.0, 1'000'000), 2 * kStepPulseHighNs);
  const StepSchedule s{.startNs = 1'000, .periodNs = 625'000};
  EXPECT_EQ(s.riseNs(0), 1'000);
  EXPECT_EQ(s.fallNs(0), 1'000 + kStepPulseHighNs);
  EXPECT_EQ(s.riseNs(3), 1'000 + 3 * 625'000);
  // 800 steps (90 degrees) take 800 periods: 0.5 s at 180 deg/s.
  EXPECT_EQ(s.endNs(800) - s.startNs, 500'000'000);
}

}  // namespace
}  // namespace smx::hal
