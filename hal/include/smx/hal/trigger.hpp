#pragma once

#include <cstdint>
#include <string_view>

#include "smx/hal/error.hpp"

// The projectors' trigger lines, by role: line i is the rig's projector i, whatever chip and
// offset the board file maps it to. A projector lights while its line is active.
namespace smx::hal {

class TriggerLines {
 public:
  virtual ~TriggerLines() = default;
  TriggerLines(const TriggerLines&) = delete;
  TriggerLines& operator=(const TriggerLines&) = delete;

  [[nodiscard]] virtual int count() const = 0;
  [[nodiscard]] virtual std::string_view role(int line) const = 0;  // e.g. "proj0"
  // Activates the lines whose bit is set in `activeMask` and deactivates the others.
  [[nodiscard]] virtual HalResult<void> set(std::uint32_t activeMask) = 0;
  [[nodiscard]] virtual std::uint32_t active() const = 0;
  // Every projector's light, percent of full (1…100), on boards whose projector drivers can be
  // dimmed; GPIO lines only switch, and refuse anything but 100.
  [[nodiscard]] virtual bool dimmable() const { return false; }
  [[nodiscard]] virtual HalResult<void> setPower(int percent) {
    if (percent != 100) {
      return halFail(HalErrc::kNotSupported,
                     "the board's trigger lines only switch its projectors on and off");
    }
    return {};
  }

 protected:
  TriggerLines() = default;
};

}  // namespace smx::hal
