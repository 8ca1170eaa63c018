#pragma once

#include <cstdint>
#include <expected>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "smx/hal/board_config.hpp"
#include "smx/hal/trigger.hpp"
#include "smx/linux/trigger_line_map.hpp"

struct gpiod_chip;
struct gpiod_line;

// hal::TriggerLines on GPIO character devices through libgpiod 1.6: each line is requested as an
// output (consumer "stripemuxd", active-low when the board says so, so 1 always means "projector
// on") and starts inactive. The lines are set inactive and released when the object goes.
namespace smx::lnx {

class GpiodTrigger final : public hal::TriggerLines {
 public:
  static constexpr const char* kConsumer = "stripemuxd";

  // Opens every chip once and requests every line (init time); the error names the chip, the
  // line and the system's reason.
  [[nodiscard]] static std::expected<std::unique_ptr<GpiodTrigger>, std::string> create(
      const hal::TriggerConfig& config);
  ~GpiodTrigger() override;
  GpiodTrigger(const GpiodTrigger&) = delete;
  GpiodTrigger& operator=(const GpiodTrigger&) = delete;

  [[nodiscard]] int count() const override { return map_.count(); }
  [[nodiscard]] std::string_view role(int line) const override { return map_.role(line); }
  [[nodiscard]] hal::HalResult<void> set(std::uint32_t activeMask) override;
  [[nodiscard]] std::uint32_t active() const override { return active_; }

 private:
  struct ChipCloser {
    void operator()(gpiod_chip* chip) const;
  };
  struct LineReleaser {
    void operator()(gpiod_line* line) const;
  };
  struct Chip {
    std::string name;
    std::unique_ptr<gpiod_chip, ChipCloser> handle;
  };

  explicit GpiodTrigger(TriggerLineMap map) : map_(std::move(map)) {}

  TriggerLineMap map_;
  std::vector<Chip> chips_;  // declared before lines_: lines are released before chips close
  std::vector<std::unique_ptr<gpiod_line, LineReleaser>> lines_;
  std::uint32_t active_ = 0;
};

}  // namespace smx::lnx
