#include "smx/linux/gpiod_turntable.hpp"

#include <gpiod.h>

#include <cerrno>
#include <cstdlib>
#include <ctime>
#include <system_error>

#include "smx/hal/turntable_motion.hpp"

namespace smx::lnx {

namespace {

std::string errnoText(int err) {
  return std::generic_category().message(err);
}

// Sleeps until `deadlineNs` on CLOCK_MONOTONIC, across signals.
void sleepUntil(std::int64_t deadlineNs) {
  timespec at{};
  at.tv_sec = static_cast<time_t>(deadlineNs / 1'000'000'000);
  at.tv_nsec = static_cast<long>(deadlineNs % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr) == EINTR) {
  }
}

std::int64_t nowNs() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return std::int64_t{now.tv_sec} * 1'000'000'000 + now.tv_nsec;
}

}  // namespace

void GpiodTurntable::ChipCloser::operator()(gpiod_chip* chip) const {
  gpiod_chip_close(chip);
}

void GpiodTurntable::LineReleaser::operator()(gpiod_line* line) const {
  gpiod_line_release(line);
}

std::expected<GpiodTurntable::Line, std::string> GpiodTurntable::request(const char* field,
                                                                         unsigned offset,
                                                                         bool activeLow,
                                                                         int initial) {
  const std::string at = std::string("turntable.") + field;
  gpiod_line* line = gpiod_chip_get_line(chip_.get(), offset);
  if (line == nullptr) {
    const int err = errno;
    return std::unexpected(
        at + ": GPIO chip '" + config_.chip + "' has no line " + std::to_string(offset) +
        " (it has " + std::to_string(gpiod_chip_num_lines(chip_.get())) + "): " + errnoText(err));
  }
  const int flags = activeLow ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
  if (gpiod_line_request_output_flags(line, kConsumer, flags, initial) != 0) {
    const int err = errno;
    return std::unexpected(at + ": cannot request line " + std::to_string(offset) +
                           " of GPIO chip '" + config_.chip + "' as an output: " + errnoText(err));
  }
  return Line(line);
}

std::expected<std::unique_ptr<GpiodTurntable>, std::string> GpiodTurntable::create(
    const hal::TurntableConfig& config) {
  std::unique_ptr<GpiodTurntable> table(new GpiodTurntable(config));
  table->periodNs_ = hal::stepPeriodNs(config.speedDegS, config.stepsPerTurn);
  // A name ("gpiochip0"), number, label or path, as the gpiod tools take it.
  table->chip_.reset(gpiod_chip_open_lookup(config.chip.c_str()));
  if (!table->chip_) {
    const int err = errno;
    return std::unexpected("turntable.chip: cannot open GPIO chip '" + config.chip +
                           "': " + errnoText(err));
  }
  auto step = table->request("step", config.stepLine, false, 0);
  if (!step) {
    return std::unexpected(step.error());
  }
  table->step_ = std::move(*step);
  auto dir = table->request("dir", config.dirLine, false, 0);
  if (!dir) {
    return std::unexpected(dir.error());
  }
  table->dir_ = std::move(*dir);
  if (config.enableLine) {
    // Active means enabled whatever the polarity; enabled from here on (holding torque).
    auto enable = table->request("enable", *config.enableLine, config.enableActiveLow, 1);
    if (!enable) {
      return std::unexpected(enable.error());
    }
    table->enable_ = std::move(*enable);
  }
  return table;
}

GpiodTurntable::~GpiodTurntable() {
  // The motor free before the line is let go: a released line may keep its last value.
  if (enable_) {
    (void)gpiod_line_set_value(enable_.get(), 0);
  }
}

hal::HalResult<void> GpiodTurntable::move(std::int32_t steps) {
  const std::int64_t count = std::abs(std::int64_t{steps});
  const std::int64_t sign = steps < 0 ? -1 : 1;
  if (gpiod_line_set_value(dir_.get(), steps < 0 ? 0 : 1) != 0) {
    return hal::halFail(hal::HalErrc::kIo, "cannot set the turntable's DIR line", errno);
  }
  // DIR settles for one pulse width before the first STEP (drivers ask for ~200 ns).
  const hal::StepSchedule schedule{.startNs = nowNs() + hal::kStepPulseHighNs,
                                   .periodNs = periodNs_};
  for (std::int64_t k = 0; k < count; ++k) {
    sleepUntil(schedule.riseNs(k));
    if (gpiod_line_set_value(step_.get(), 1) != 0) {
      return hal::halFail(hal::HalErrc::kIo, "cannot set the turntable's STEP line", errno);
    }
    sleepUntil(schedule.fallNs(k));
    if (gpiod_line_set_value(step_.get(), 0) != 0) {
      return hal::halFail(hal::HalErrc::kIo, "cannot set the turntable's STEP line", errno);
    }
    position_ += sign;  // the driver steps on the rising edge
  }
  sleepUntil(schedule.endNs(count) + std::int64_t{config_.settleMs} * 1'000'000);
  return {};
}

}  // namespace smx::lnx
