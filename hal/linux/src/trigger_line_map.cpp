#include "smx/linux/trigger_line_map.hpp"

#include <utility>

namespace smx::lnx {

namespace {

std::string field(std::size_t index, const char* name) {
  return "trigger.lines[" + std::to_string(index) + "]." + name;
}

bool isActive(std::uint32_t mask, int line) {
  return ((mask >> static_cast<unsigned>(line)) & 1U) != 0;
}

}  // namespace

std::expected<TriggerLineMap, std::string> TriggerLineMap::create(
    const hal::TriggerConfig& config) {
  const auto& lines = config.lines;
  if (lines.size() > static_cast<std::size_t>(kMaxLines)) {
    return std::unexpected("trigger.lines: " + std::to_string(lines.size()) + " lines, at most " +
                           std::to_string(kMaxLines));
  }
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].role.empty()) {
      return std::unexpected(field(i, "role") + " is empty");
    }
    if (lines[i].chip.empty()) {
      return std::unexpected(field(i, "chip") + " is empty");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (lines[j].role == lines[i].role) {
        return std::unexpected(field(i, "role") + ": '" + lines[i].role + "' is also line " +
                               std::to_string(j));
      }
      if (lines[j].chip == lines[i].chip && lines[j].offset == lines[i].offset) {
        return std::unexpected(field(i, "offset") + ": " + lines[i].chip + " line " +
                               std::to_string(lines[i].offset) + " is also line " +
                               std::to_string(j));
      }
    }
  }
  return TriggerLineMap(config);
}

std::string_view TriggerLineMap::role(int line) const {
  if (line < 0 || line >= count()) {
    return {};
  }
  return config_.lines[static_cast<std::size_t>(line)].role;
}

int TriggerLineMap::find(std::string_view role) const {
  for (int i = 0; i < count(); ++i) {
    if (config_.lines[static_cast<std::size_t>(i)].role == role) {
      return i;
    }
  }
  return -1;
}

bool TriggerLineMap::fits(std::uint32_t activeMask) const {
  return count() == kMaxLines || (activeMask >> static_cast<unsigned>(count())) == 0;
}

std::span<const LineWrite> TriggerLineMap::writeOrder(std::uint32_t activeMask,
                                                      std::span<LineWrite, kMaxLines> out) const {
  std::size_t n = 0;
  for (const bool active : {false, true}) {
    for (int i = 0; i < count(); ++i) {
      if (isActive(activeMask, i) == active) {
        out[n++] = LineWrite{.line = i, .active = active};
      }
    }
  }
  return std::span<const LineWrite>(out).first(n);
}

}  // namespace smx::lnx
