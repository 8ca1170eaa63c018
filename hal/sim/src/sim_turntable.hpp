#pragma once

#include <atomic>
#include <cstdint>

#include "smx/hal/board_config.hpp"
#include "smx/hal/clock.hpp"
#include "smx/hal/turntable.hpp"
#include "smx/hal/turntable_motion.hpp"

// The simulated board's turntable: a move takes the time the board's speed gives it and then its
// settle time, on the board's clock, and the simulated cameras render the scene's turntable
// objects at the angle it holds. The angle changes at the end of the motion (the capture loop,
// the only reader that matters, is blocked until then). Allocation-free.
namespace smx::sim {

class SimTurntable final : public hal::Turntable {
 public:
  SimTurntable(const hal::TurntableConfig& config, hal::Clock& clock)
      : stepsPerTurn_(config.stepsPerTurn),
        periodNs_(hal::stepPeriodNs(config.speedDegS, config.stepsPerTurn)),
        settleNs_(std::int64_t{config.settleMs} * 1'000'000),
        clock_(clock) {}

  [[nodiscard]] std::int32_t stepsPerTurn() const override { return stepsPerTurn_; }
  [[nodiscard]] std::int64_t position() const override { return position_; }
  [[nodiscard]] hal::HalResult<void> move(std::int32_t steps) override;

  // Degrees, right-handed about the scene's turntable axis (what the renderer takes).
  [[nodiscard]] double angleDeg() const;

 private:
  std::int32_t stepsPerTurn_;
  std::int64_t periodNs_;
  std::int64_t settleNs_;
  hal::Clock& clock_;
  std::atomic<std::int64_t> position_ = 0;  // the capture loop moves, cameras read
};

}  // namespace smx::sim
