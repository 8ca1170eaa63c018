#include "sim_turntable.hpp"

#include <cstdlib>

namespace smx::sim {

hal::HalResult<void> SimTurntable::move(std::int32_t steps) {
  const std::int64_t start = clock_.nowNs();
  const hal::StepSchedule schedule{.startNs = start, .periodNs = periodNs_};
  clock_.sleepUntilNs(schedule.endNs(std::abs(std::int64_t{steps})));
  position_ += steps;
  clock_.sleepUntilNs(clock_.nowNs() + settleNs_);
  return {};
}

double SimTurntable::angleDeg() const {
  const std::int64_t p = position_;
  return static_cast<double>(p) * 360.0 / static_cast<double>(stepsPerTurn_);
}

}  // namespace smx::sim
