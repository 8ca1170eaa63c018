#pragma once

#include <array>

// The noise bound of the health check (docs/health-check.md): the value that
// λ₁·z₁² + λ₂·z₂² + λ₃·z₃², z independent standard normal, exceeds with probability `tail`.
// A fitted plane's mean square over the image, under pure noise, is σ² times such a sum. Host
// code.
namespace smx::health {

// weights ≥ 0 in any order; tail in (0, 1).
[[nodiscard]] double weightedChiSquareQuantile(std::array<double, 3> weights, double tail);

}  // namespace smx::health
