#include "smx/linux/gpiod_trigger.hpp"

#include <gpiod.h>

#include <array>
#include <cerrno>
#include <system_error>

namespace smx::lnx {

namespace {

std::string errnoText(int err) {
  return std::generic_category().message(err);
}

std::string lineName(std::size_t index) {
  return "trigger.lines[" + std::to_string(index) + "]";
}

}  // namespace

void GpiodTrigger::ChipCloser::operator()(gpiod_chip* chip) const {
  gpiod_chip_close(chip);
}

void GpiodTrigger::LineReleaser::operator()(gpiod_line* line) const {
  gpiod_line_release(line);
}

std::expected<std::unique_ptr<GpiodTrigger>, std::string> GpiodTrigger::create(
    const hal::TriggerConfig& config) {
  auto map = TriggerLineMap::create(config);
  if (!map) {
    return std::unexpected(map.error());
  }
  std::unique_ptr<GpiodTrigger> trigger(new GpiodTrigger(std::move(*map)));
  for (std::size_t i = 0; i < config.lines.size(); ++i) {
    const hal::TriggerLineConfig& line = config.lines[i];
    Chip* chip = nullptr;
    for (Chip& open : trigger->chips_) {
      if (open.name == line.chip) {
        chip = &open;
      }
    }
    if (chip == nullptr) {
      // A name ("gpiochip0"), number, label or path, as the gpiod tools take it.
      gpiod_chip* handle = gpiod_chip_open_lookup(line.chip.c_str());
      if (handle == nullptr) {
        const int err = errno;
        return std::unexpected(lineName(i) + ".chip: cannot open GPIO chip '" + line.chip +
                               "': " + errnoText(err));
      }
      chip = &trigger->chips_.emplace_back(
          Chip{.name = line.chip, .handle = std::unique_ptr<gpiod_chip, ChipCloser>(handle)});
    }
    gpiod_line* handle = gpiod_chip_get_line(chip->handle.get(), line.offset);
    if (handle == nullptr) {
      const int err = errno;
      return std::unexpected(lineName(i) + ".offset: GPIO chip '" + line.chip + "' has no line " +
                             std::to_string(line.offset) + " (it has " +
                             std::to_string(gpiod_chip_num_lines(chip->handle.get())) +
                             "): " + errnoText(err));
    }
    const int flags = line.activeLow ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
    if (gpiod_line_request_output_flags(handle, kConsumer, flags, 0) != 0) {
      const int err = errno;
      return std::unexpected(lineName(i) + ": cannot request line " + std::to_string(line.offset) +
                             " of GPIO chip '" + line.chip + "' as an output: " + errnoText(err));
    }
    trigger->lines_.emplace_back(handle);
  }
  return trigger;
}

GpiodTrigger::~GpiodTrigger() {
  // Projectors off before the lines are let go: a released line may keep its last value.
  (void)set(0);
}

hal::HalResult<void> GpiodTrigger::set(std::uint32_t activeMask) {
  if (!map_.fits(activeMask)) {
    return hal::halFail(hal::HalErrc::kInvalidArgument, "the mask names a line that is not there");
  }
  std::array<LineWrite, TriggerLineMap::kMaxLines> scratch{};
  for (const LineWrite& write : map_.writeOrder(activeMask, scratch)) {
    const auto index = static_cast<std::size_t>(write.line);
    if (index >= lines_.size()) {
      break;  // a partly created trigger being destroyed
    }
    if (gpiod_line_set_value(lines_[index].get(), write.active ? 1 : 0) != 0) {
      return hal::halFail(hal::HalErrc::kIo, "cannot set a trigger line", errno);
    }
    const std::uint32_t bit = 1U << static_cast<unsigned>(write.line);
    active_ = write.active ? (active_ | bit) : (active_ & ~bit);
  }
  return {};
}

}  // namespace smx::lnx
