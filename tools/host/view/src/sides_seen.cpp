#include "smx/view/sides_seen.hpp"

#include <algorithm>
#include <cmath>

namespace smx::view {

void SidesSeen::add(double azimuthDeg) {
  constexpr double kSectorDeg = 30.0;
  for (std::size_t k = 0; k < seen_.size(); ++k) {
    const double middle = kSectorDeg * (static_cast<double>(k) + 0.5);
    const double apart = std::fmod(std::fabs(azimuthDeg - middle), 360.0);
    seen_[k] = seen_[k] || std::min(apart, 360.0 - apart) <= kSectorDeg;
  }
}

double SidesSeen::percent() const {
  return 100.0 * static_cast<double>(std::ranges::count(seen_, true)) /
         static_cast<double>(seen_.size());
}

}  // namespace smx::view
