#pragma once

#include <cstdint>
#include <optional>

// The arithmetic of a stepper turntable, shared by its backends, the firmware and tests: angles
// in micro-degrees (the wire's unit) to and from steps, and the timing of a move. Pure.
namespace smx::hal {

inline constexpr std::int64_t kMicroDegPerTurn = 360'000'000;
// A STEP pulse stays high at least this long (stepper drivers ask for 1-2 us).
inline constexpr std::int64_t kStepPulseHighNs = 2'000;

// position · 360e6 / stepsPerTurn, rounded half away from zero.
[[nodiscard]] std::int64_t angleMicroDeg(std::int64_t position, std::int32_t stepsPerTurn);

// The step nearest to `angleMicroDeg` (half away from zero); nullopt when stepsPerTurn is not
// positive.
[[nodiscard]] std::optional<std::int64_t> stepsForAngle(std::int64_t angleMicroDeg,
                                                        std::int32_t stepsPerTurn);

// The steps a turn request drives from `position`: `angleMicroDeg` more (relative) or to that
// angle (absolute). nullopt when the move is beyond one int32 of steps (a move is split by no
// one: the caller refuses it) or stepsPerTurn is not positive.
[[nodiscard]] std::optional<std::int32_t> stepsToMove(std::int64_t position,
                                                      std::int32_t stepsPerTurn, bool absolute,
                                                      std::int64_t angleMicroDeg);

// The STEP period at `speedDegS`, at least twice the high time (a pulse then a low as long).
[[nodiscard]] std::int64_t stepPeriodNs(double speedDegS, std::int32_t stepsPerTurn);

// The pulse schedule of a move: pulse k (0-based) rises at startNs + k·period and falls
// kStepPulseHighNs later; the move is over one period after the last rise.
struct StepSchedule {
  std::int64_t startNs = 0;
  std::int64_t periodNs = 0;
  [[nodiscard]] std::int64_t riseNs(std::int64_t k) const { return startNs + k * periodNs; }
  [[nodiscard]] std::int64_t fallNs(std::int64_t k) const { return riseNs(k) + kStepPulseHighNs; }
  [[nodiscard]] std::int64_t endNs(std::int64_t steps) const { return riseNs(steps); }
};

}  // namespace smx::hal
