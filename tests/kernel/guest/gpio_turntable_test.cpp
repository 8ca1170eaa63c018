// The turntable's STEP/DIR/ENABLE lines on the kernel's gpio-sim, in a qemu guest (tests/kernel,
// turntable): GpiodTurntable drives gpio-sim lines 2 (STEP), 3 (DIR) and 4 (ENABLE), and the
// kernel's gpio_value tracepoint records every value the lines were set to, so each STEP edge is
// counted exactly, however short the pulse (gpio-sim's sysfs value is too slow to sample them).
//
// Environment: SMX_GPIO_SIM (gpio-sim's sysfs folder of the chip, holding sim_gpio<N>/value; its
// name is the chip's), SMX_TRACEFS (the mounted tracefs).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "smx/hal/turntable_motion.hpp"
#include "smx/linux/gpiod_turntable.hpp"

namespace smx {
namespace {

std::string env(const char* name) {
  const char* value = std::getenv(name);  // NOLINT(concurrency-mt-unsafe): read before threads
  return value != nullptr ? value : "";
}

std::int64_t monotonicNs() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// One gpio_value or gpio_direction event of the trace.
struct Event {
  bool value = false;  // gpio_value (else gpio_direction)
  unsigned gpio = 0;
  bool set = false;  // gpio_value: "set" (else "get"); gpio_direction: "out"
  int level = 0;
};

std::vector<Event> events(const std::string& trace) {
  std::vector<Event> out;
  std::istringstream lines(trace);
  std::string line;
  while (std::getline(lines, line)) {
    Event e;
    char word[8] = {};
    if (const auto at = line.find("gpio_value: "); at != std::string::npos) {
      e.value = true;
      if (std::sscanf(line.c_str() + at + 12, "%u %3s %d", &e.gpio, word, &e.level) == 3) {
        e.set = std::string(word) == "set";
        out.push_back(e);
      }
    } else if (const auto dir = line.find("gpio_direction: "); dir != std::string::npos) {
      if (std::sscanf(line.c_str() + dir + 16, "%u %3s", &e.gpio, word) == 2) {
        e.set = std::string(word) == "out";
        out.push_back(e);
      }
    }
  }
  return out;
}

struct Counted {
  int stepRises = 0;
  int stepFalls = 0;
  int dirSets = 0;
  int lastDir = -1;
  bool dirBeforeFirstStep = false;
};

Counted count(const std::vector<Event>& trace, unsigned step, unsigned dir) {
  Counted c;
  for (const Event& e : trace) {
    if (!e.value || !e.set) {
      continue;
    }
    if (e.gpio == step) {
      c.stepRises += e.level == 1 ? 1 : 0;
      c.stepFalls += e.level == 0 ? 1 : 0;
    } else if (e.gpio == dir) {
      ++c.dirSets;
      c.lastDir = e.level;
      c.dirBeforeFirstStep = c.dirBeforeFirstStep || c.stepRises == 0;
    }
  }
  return c;
}

TEST(GpioSimTurntable, EveryStepIsOneEdgeAndDirFollowsTheSign) {
  const std::string sim = env("SMX_GPIO_SIM");
  const std::string tracefs = env("SMX_TRACEFS");
  if (sim.empty() || tracefs.empty()) {
    GTEST_SKIP() << "needs SMX_GPIO_SIM and SMX_TRACEFS (tests/kernel/cases/turntable.sh)";
  }
  writeFile(tracefs + "/trace", "");
  writeFile(tracefs + "/events/gpio/enable", "1");
  writeFile(tracefs + "/tracing_on", "1");

  // 200 steps per turn at 360 deg/s: 5 ms a step.
  hal::TurntableConfig config;
  config.chip = std::filesystem::path(sim).filename().string();
  config.stepLine = 2;
  config.dirLine = 3;
  config.enableLine = 4;
  config.enableActiveLow = true;
  config.stepsPerTurn = 200;
  config.speedDegS = 360.0;
  config.settleMs = 20;
  auto table = lnx::GpiodTurntable::create(config);
  ASSERT_TRUE(table.has_value()) << table.error();
  // The lines were requested as outputs in the order STEP, DIR, ENABLE: their global numbers.
  std::vector<unsigned> outputs;
  for (const Event& e : events(readFile(tracefs + "/trace"))) {
    if (!e.value && e.set) {
      outputs.push_back(e.gpio);
    }
  }
  ASSERT_EQ(outputs.size(), 3U);
  const unsigned step = outputs[0];
  const unsigned dir = outputs[1];
  EXPECT_EQ(dir, step + 1);
  EXPECT_EQ(outputs[2], step + 2);
  // Enabled (active low: the line reads 0) from create() on.
  EXPECT_EQ(readFile(sim + "/sim_gpio4/value").substr(0, 1), "0");

  const std::int64_t period = hal::stepPeriodNs(360.0, 200);
  EXPECT_EQ(period, 5'000'000);
  for (const int steps : {37, -12}) {
    writeFile(tracefs + "/trace", "");
    const std::int64_t start = monotonicNs();
    ASSERT_TRUE((*table)->move(steps).has_value());
    const std::int64_t took = monotonicNs() - start;
    const Counted c = count(events(readFile(tracefs + "/trace")), step, dir);
    EXPECT_EQ(c.stepRises, std::abs(steps)) << "move " << steps;
    EXPECT_EQ(c.stepFalls, std::abs(steps)) << "move " << steps;
    EXPECT_EQ(c.dirSets, 1) << "move " << steps;
    EXPECT_TRUE(c.dirBeforeFirstStep);
    EXPECT_EQ(c.lastDir, steps > 0 ? 1 : 0) << "move " << steps;
    // The deadlines are absolute: a move never ends before its schedule and settle.
    EXPECT_GE(took, std::abs(steps) * period + 20'000'000) << "move " << steps;
    EXPECT_EQ(readFile(sim + "/sim_gpio2/value").substr(0, 1), "0");  // STEP rests low
  }
  EXPECT_EQ((*table)->position(), 25);
  std::printf("SMX-FIGURE: turntable steps counted on gpio-sim: 37 forward, 12 back\n");
}

}  // namespace
}  // namespace smx
