#include "smx/config/rotation_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <span>
#include <string>

#include "smx/config/json_text.hpp"

namespace smx::config {

std::optional<std::string> rotationProblem(std::span<const double, 9> r) {
  double deviation = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      double rrt = 0;
      for (std::size_t k = 0; k < 3; ++k) {
        rrt += r[3 * i + k] * r[3 * j + k];
      }
      deviation = std::max(deviation, std::abs(rrt - (i == j ? 1.0 : 0.0)));
    }
  }
  if (!(deviation <= kRotationTolerance)) {
    return "not a rotation: max |R*R^T - I| is " + formatDeviation(deviation) +
           " (must be at most " + formatDeviation(kRotationTolerance) + ")";
  }
  const double det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) +
                     r[2] * (r[3] * r[7] - r[4] * r[6]);
  if (!(std::abs(det - 1) <= kRotationTolerance)) {
    return "not a rotation: det R is " + formatDeviation(det) + " (must be 1 within " +
           formatDeviation(kRotationTolerance) + (det < 0 ? "; det -1 is a reflection)" : ")");
  }
  return std::nullopt;
}

}  // namespace smx::config
