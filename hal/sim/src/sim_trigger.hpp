#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "smx/hal/clock.hpp"
#include "smx/hal/trigger.hpp"
#include "smx/sim/sim_board.hpp"

// The simulated board's trigger lines: a mask the simulated cameras read at exposure, and a log
// of every edge for tests. Allocation-free after construction.
namespace smx::sim {

class SimTrigger final : public hal::TriggerLines {
 public:
  SimTrigger(std::vector<std::string> roles, const hal::Clock& clock, bool dimmable)
      : roles_(std::move(roles)), clock_(clock), dimmable_(dimmable) {}

  [[nodiscard]] int count() const override { return static_cast<int>(roles_.size()); }
  [[nodiscard]] std::string_view role(int line) const override {
    return roles_.at(static_cast<std::size_t>(line));
  }
  [[nodiscard]] hal::HalResult<void> set(std::uint32_t activeMask) override;
  [[nodiscard]] std::uint32_t active() const override;
  [[nodiscard]] bool dimmable() const override { return dimmable_; }
  [[nodiscard]] hal::HalResult<void> setPower(int percent) override;
  [[nodiscard]] int power() const { return power_; }

  [[nodiscard]] std::vector<TriggerEdge> edges() const;

 private:
  static constexpr std::size_t kLogSize = 4096;

  std::vector<std::string> roles_;
  const hal::Clock& clock_;
  bool dimmable_;
  mutable std::mutex mutex_;  // tests read the log while the firmware drives the lines
  std::uint32_t active_ = 0;
  std::atomic<int> power_ = 100;
  std::array<TriggerEdge, kLogSize> log_{};
  std::uint64_t logged_ = 0;
};

}  // namespace smx::sim
