#pragma once

#include <array>
#include <cstdint>
#include <expected>
#include <span>
#include <string>
#include <string_view>

#include "smx/hal/board_config.hpp"

// The chip-independent half of the GPIO trigger: which line has which role, and in what order a
// new mask is written. Separate from GpiodTrigger so it is tested without a GPIO chip.
namespace smx::lnx {

struct LineWrite {
  int line = 0;  // index into TriggerConfig::lines (the rig's projector order)
  bool active = false;
  friend bool operator==(const LineWrite&, const LineWrite&) = default;
};

class TriggerLineMap {
 public:
  static constexpr int kMaxLines = 32;  // one bit of the mask per line

  // Checks the lines (count, non-empty roles and chips, no role or chip:offset twice); the error
  // names the field, e.g. "trigger.lines[2].chip".
  [[nodiscard]] static std::expected<TriggerLineMap, std::string> create(
      const hal::TriggerConfig& config);

  [[nodiscard]] int count() const { return static_cast<int>(config_.lines.size()); }
  // Empty for an index out of range.
  [[nodiscard]] std::string_view role(int line) const;
  [[nodiscard]] const hal::TriggerLineConfig& line(int index) const {
    return config_.lines[static_cast<std::size_t>(index)];
  }
  // The line with this role, or -1.
  [[nodiscard]] int find(std::string_view role) const;
  // True when the mask only names lines that exist.
  [[nodiscard]] bool fits(std::uint32_t activeMask) const;

  // One write per line for `activeMask`, deactivations first: two projectors never light
  // together while the mask changes from one to the other. Returns the used part of `out`.
  [[nodiscard]] std::span<const LineWrite> writeOrder(std::uint32_t activeMask,
                                                      std::span<LineWrite, kMaxLines> out) const;

 private:
  explicit TriggerLineMap(hal::TriggerConfig config) : config_(std::move(config)) {}

  hal::TriggerConfig config_;
};

}  // namespace smx::lnx
