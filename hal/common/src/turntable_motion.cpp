#include "smx/hal/turntable_motion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace smx::hal {

namespace {

// Products of a step count and micro-degrees need more than 64 bits.
__extension__ typedef __int128 Wide;  // NOLINT(modernize-use-using): __extension__ needs typedef

constexpr Wide kInt64Max = std::numeric_limits<std::int64_t>::max();
constexpr Wide kInt64Min = std::numeric_limits<std::int64_t>::min();

// round(numerator / denominator), half away from zero; denominator > 0.
Wide divideRounded(Wide numerator, Wide denominator) {
  const Wide half = denominator / 2;
  return numerator >= 0 ? (numerator + half) / denominator : -((-numerator + half) / denominator);
}

}  // namespace

std::int64_t angleMicroDeg(std::int64_t position, std::int32_t stepsPerTurn) {
  if (stepsPerTurn <= 0) {
    return 0;
  }
  // |position| < 2^63 and 360e6 < 2^29: the product fits 128 bits; the quotient saturates.
  const Wide angle = divideRounded(static_cast<Wide>(position) * kMicroDegPerTurn, stepsPerTurn);
  return static_cast<std::int64_t>(std::clamp(angle, kInt64Min, kInt64Max));
}

std::optional<std::int64_t> stepsForAngle(std::int64_t angleMicroDeg, std::int32_t stepsPerTurn) {
  if (stepsPerTurn <= 0) {
    return std::nullopt;
  }
  // The quotient is smaller than the angle: it always fits.
  return static_cast<std::int64_t>(
      divideRounded(static_cast<Wide>(angleMicroDeg) * stepsPerTurn, kMicroDegPerTurn));
}

std::optional<std::int32_t> stepsToMove(std::int64_t position, std::int32_t stepsPerTurn,
                                        bool absolute, std::int64_t angleMicroDeg) {
  const auto steps = stepsForAngle(angleMicroDeg, stepsPerTurn);
  if (!steps) {
    return std::nullopt;
  }
  const Wide move = absolute ? static_cast<Wide>(*steps) - position : *steps;
  if (move > std::numeric_limits<std::int32_t>::max() ||
      move < std::numeric_limits<std::int32_t>::min()) {
    return std::nullopt;
  }
  return static_cast<std::int32_t>(move);
}

std::int64_t stepPeriodNs(double speedDegS, std::int32_t stepsPerTurn) {
  const double stepsPerS = std::max(speedDegS, 1e-9) / 360.0 * std::max(stepsPerTurn, 1);
  const double period = std::round(1e9 / stepsPerS);
  // One step per hour at the slowest: any board's table turns faster.
  return std::clamp(static_cast<std::int64_t>(std::min(period, 3.6e12)), 2 * kStepPulseHighNs,
                    std::int64_t{3'600'000'000'000});
}

}  // namespace smx::hal
