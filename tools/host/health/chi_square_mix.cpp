#include "smx/health/chi_square_mix.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

namespace smx::health {

namespace {

// Midpoint grid of the two smaller terms in polar form (z₂, z₃) = r·(cos a, sin a). The
// integrand is smooth and periodic in a, and e^(−r²/2) is below 1e−14 past r = 8.
constexpr int kRadii = 160;
constexpr double kMaxRadius = 8.0;
constexpr int kAngles = 16;
constexpr int kBisections = 30;

// P(λ₁·z₁² > s) for the largest weight.
double largestTermExceeds(double lambda1, double s) {
  return s <= 0 ? 1.0 : std::erfc(std::sqrt(s / (2.0 * lambda1)));
}

// P(λ₁z₁² + λ₂z₂² + λ₃z₃² > t): the largest term in closed form, the other two integrated.
double tailProbability(const std::array<double, 3>& w, double t) {
  const double dr = kMaxRadius / kRadii;
  const double da = 0.5 * std::numbers::pi / kAngles;
  double sum = 0;
  for (int i = 0; i < kAngles; ++i) {
    const double a = (i + 0.5) * da;
    const double spread = w[1] * std::cos(a) * std::cos(a) + w[2] * std::sin(a) * std::sin(a);
    for (int j = 0; j < kRadii; ++j) {
      const double r = (j + 0.5) * dr;
      sum += std::exp(-0.5 * r * r) * r * largestTermExceeds(w[0], t - spread * r * r);
    }
  }
  // (1 / 2π) over the full circle; the quarter taken here is multiplied by 4.
  return sum * dr * da * 2.0 / std::numbers::pi;
}

}  // namespace

double weightedChiSquareQuantile(std::array<double, 3> weights, double tail) {
  for (double& w : weights) {
    w = std::max(w, 0.0);
  }
  std::ranges::sort(weights, std::greater<>());
  if (weights[0] <= 0) {
    return 0;
  }
  // The sum is at most λ₁·χ²₃, whose quantile is below 3 + 2L + 2√(3L), L = ln(1/tail)
  // (Laurent and Massart, 2000); bisect on a log scale.
  const double logTail = std::log(1.0 / tail);
  double lo = weights[0] * 1e-3;
  double hi = weights[0] * (3.0 + 2.0 * logTail + 2.0 * std::sqrt(3.0 * logTail)) * 1.01;
  for (int i = 0; i < kBisections; ++i) {
    const double mid = std::sqrt(lo * hi);
    if (tailProbability(weights, mid) > tail) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return std::sqrt(lo * hi);
}

}  // namespace smx::health
