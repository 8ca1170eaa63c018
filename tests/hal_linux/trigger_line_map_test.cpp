#include "smx/linux/trigger_line_map.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "smx/linux/gpiod_trigger.hpp"

namespace smx::lnx {
namespace {

hal::TriggerConfig threeLines() {
  hal::TriggerConfig config;
  config.lines = {{.role = "proj0", .chip = "gpiochip0", .offset = 17, .activeLow = false},
                  {.role = "proj1", .chip = "gpiochip0", .offset = 27, .activeLow = true},
                  {.role = "proj2", .chip = "gpiochip1", .offset = 17, .activeLow = false}};
  return config;
}

std::string errorOf(const hal::TriggerConfig& config) {
  auto map = TriggerLineMap::create(config);
  return map ? std::string("(accepted)") : map.error();
}

TEST(TriggerLineMap, RolesAreInTheBoardsLineOrder) {
  auto map = TriggerLineMap::create(threeLines());
  ASSERT_TRUE(map) << map.error();
  EXPECT_EQ(map->count(), 3);
  EXPECT_EQ(map->role(0), "proj0");
  EXPECT_EQ(map->role(2), "proj2");
  EXPECT_EQ(map->role(3), "");
  EXPECT_EQ(map->role(-1), "");
  EXPECT_EQ(map->find("proj1"), 1);
  EXPECT_EQ(map->find("proj9"), -1);
  EXPECT_TRUE(map->line(1).activeLow);
}

TEST(TriggerLineMap, ErrorsNameTheField) {
  auto config = threeLines();
  config.lines[1].role.clear();
  EXPECT_EQ(errorOf(config), "trigger.lines[1].role is empty");

  config = threeLines();
  config.lines[2].chip.clear();
  EXPECT_EQ(errorOf(config), "trigger.lines[2].chip is empty");

  config = threeLines();
  config.lines[2].role = "proj0";
  EXPECT_EQ(errorOf(config), "trigger.lines[2].role: 'proj0' is also line 0");

  config = threeLines();
  config.lines[2].chip = "gpiochip0";  // offset 17 on gpiochip0 is line 0's
  EXPECT_EQ(errorOf(config), "trigger.lines[2].offset: gpiochip0 line 17 is also line 0");

  config.lines.clear();
  for (unsigned i = 0; i < 33; ++i) {
    config.lines.push_back({.role = "p" + std::to_string(i), .chip = "c", .offset = i});
  }
  EXPECT_EQ(errorOf(config), "trigger.lines: 33 lines, at most 32");
  config.lines.pop_back();
  EXPECT_EQ(errorOf(config), "(accepted)");
}

TEST(TriggerLineMap, MasksMayOnlyNameExistingLines) {
  auto map = TriggerLineMap::create(threeLines());
  ASSERT_TRUE(map);
  EXPECT_TRUE(map->fits(0b111));
  EXPECT_TRUE(map->fits(0));
  EXPECT_FALSE(map->fits(0b1000));
  EXPECT_FALSE(map->fits(0x8000'0000));

  hal::TriggerConfig full;
  for (unsigned i = 0; i < 32; ++i) {
    full.lines.push_back({.role = "p" + std::to_string(i), .chip = "c", .offset = i});
  }
  auto fullMap = TriggerLineMap::create(full);
  ASSERT_TRUE(fullMap);
  EXPECT_TRUE(fullMap->fits(0xFFFF'FFFF));
}

TEST(TriggerLineMap, WritesDeactivateBeforeTheyActivate) {
  auto map = TriggerLineMap::create(threeLines());
  ASSERT_TRUE(map);
  std::array<LineWrite, TriggerLineMap::kMaxLines> scratch{};
  // Given mask 0b101: projector 1 off first, then 0 and 2 on
  auto writes = map->writeOrder(0b101, scratch);
  const std::vector<LineWrite> want{
      {.line = 1, .active = false}, {.line = 0, .active = true}, {.line = 2, .active = true}};
  EXPECT_EQ(std::vector<LineWrite>(writes.begin(), writes.end()), want);
  // Every line is written, even when nothing is active.
  auto off = map->writeOrder(0, scratch);
  ASSERT_EQ(off.size(), 3U);
  for (const LineWrite& w : off) {
    EXPECT_FALSE(w.active);
  }
}

TEST(GpiodTrigger, AMissingChipIsNamedWithItsField) {
  // Given a board whose line is on a chip that does not exist
  hal::TriggerConfig config;
  config.lines = {{.role = "proj0", .chip = "smx-no-such-gpiochip", .offset = 3}};
  auto trigger = GpiodTrigger::create(config);
  ASSERT_FALSE(trigger);
  EXPECT_NE(trigger.error().find("trigger.lines[0].chip"), std::string::npos) << trigger.error();
  EXPECT_NE(trigger.error().find("'smx-no-such-gpiochip'"), std::string::npos) << trigger.error();
}

TEST(GpiodTrigger, InvalidLinesAreRejectedBeforeAnyChipIsOpened) {
  auto config = threeLines();
  config.lines[1].role = "proj0";
  auto trigger = GpiodTrigger::create(config);
  ASSERT_FALSE(trigger);
  EXPECT_EQ(trigger.error(), "trigger.lines[1].role: 'proj0' is also line 0");
}

TEST(GpiodTrigger, WithoutLinesOnlyTheEmptyMaskIsValid) {
  auto trigger = GpiodTrigger::create(hal::TriggerConfig{});
  ASSERT_TRUE(trigger) << trigger.error();
  EXPECT_EQ((*trigger)->count(), 0);
  EXPECT_TRUE((*trigger)->set(0));
  EXPECT_EQ((*trigger)->set(1).error().code, hal::HalErrc::kInvalidArgument);
  EXPECT_EQ((*trigger)->active(), 0U);
}

}  // namespace
}  // namespace smx::lnx
