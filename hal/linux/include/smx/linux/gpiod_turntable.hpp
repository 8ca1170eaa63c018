#pragma once

#include <atomic>
#include <cstdint>
#include <expected>
#include <memory>
#include <string>
#include <utility>

#include "smx/hal/board_config.hpp"
#include "smx/hal/turntable.hpp"

struct gpiod_chip;
struct gpiod_line;

// hal::Turntable on a STEP/DIR stepper driver through libgpiod 1.6 (docs/boards.md, "Turntable"):
// STEP, DIR and the optional ENABLE are requested as outputs (consumer "stripemuxd"). The driver
// is enabled at create() and stays enabled, holding the table where the step count says, until
// the object goes (then it is disabled and the lines released). A move sets DIR, then pulses STEP
// on the schedule of turntable_motion.hpp with absolute CLOCK_MONOTONIC deadlines (a late wake
// delays one pulse, never the ones after it), then waits the settle time.
namespace smx::lnx {

class GpiodTurntable final : public hal::Turntable {
 public:
  static constexpr const char* kConsumer = "stripemuxd";

  // Opens the chip and requests the lines (init time); the error names the field, the chip, the
  // line and the system's reason.
  [[nodiscard]] static std::expected<std::unique_ptr<GpiodTurntable>, std::string> create(
      const hal::TurntableConfig& config);
  ~GpiodTurntable() override;
  GpiodTurntable(const GpiodTurntable&) = delete;
  GpiodTurntable& operator=(const GpiodTurntable&) = delete;

  [[nodiscard]] std::int32_t stepsPerTurn() const override { return config_.stepsPerTurn; }
  [[nodiscard]] std::int64_t position() const override { return position_; }
  [[nodiscard]] hal::HalResult<void> move(std::int32_t steps) override;

 private:
  struct ChipCloser {
    void operator()(gpiod_chip* chip) const;
  };
  struct LineReleaser {
    void operator()(gpiod_line* line) const;
  };
  using Line = std::unique_ptr<gpiod_line, LineReleaser>;

  explicit GpiodTurntable(hal::TurntableConfig config) : config_(std::move(config)) {}
  [[nodiscard]] std::expected<Line, std::string> request(const char* field, unsigned offset,
                                                         bool activeLow, int initial);

  hal::TurntableConfig config_;
  std::int64_t periodNs_ = 0;
  std::unique_ptr<gpiod_chip, ChipCloser> chip_;  // declared before the lines: released first
  Line step_;
  Line dir_;
  Line enable_;                             // null: the board has no ENABLE line
  std::atomic<std::int64_t> position_ = 0;  // the capture loop moves, the network thread reads
};

}  // namespace smx::lnx
