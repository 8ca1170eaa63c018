#include "sim_trigger.hpp"

namespace smx::sim {

hal::HalResult<void> SimTrigger::set(std::uint32_t activeMask) {
  if (count() < 32 && (activeMask >> count()) != 0) {
    return hal::halFail(hal::HalErrc::kInvalidArgument,
                        "trigger mask names a line the board lacks");
  }
  const std::lock_guard lock(mutex_);
  if (activeMask != active_) {
    active_ = activeMask;
    log_[logged_ % kLogSize] = TriggerEdge{clock_.nowNs(), activeMask};
    ++logged_;
  }
  return {};
}

hal::HalResult<void> SimTrigger::setPower(int percent) {
  if (!dimmable_ && percent != 100) {
    return hal::halFail(hal::HalErrc::kNotSupported,
                        "a replaying simulated board cannot dim its projectors");
  }
  if (percent < 1 || percent > 100) {
    return hal::halFail(hal::HalErrc::kInvalidArgument, "projector power must be 1 to 100 %");
  }
  power_ = percent;
  return {};
}

std::uint32_t SimTrigger::active() const {
  const std::lock_guard lock(mutex_);
  return active_;
}

std::vector<TriggerEdge> SimTrigger::edges() const {
  const std::lock_guard lock(mutex_);
  std::vector<TriggerEdge> out;
  const std::uint64_t first = logged_ > kLogSize ? logged_ - kLogSize : 0;
  for (std::uint64_t i = first; i < logged_; ++i) {
    out.push_back(log_[i % kLogSize]);
  }
  return out;
}

}  // namespace smx::sim
