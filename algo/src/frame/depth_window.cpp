#include "smx/algo/depth_window.hpp"

namespace smx::algo {

void applyDepthWindow(DepthPlane depth, ImageView<std::uint8_t> confidence,
                      const DepthWindow& window) {
  for (int y = 0; y < depth.height(); ++y) {
    std::uint16_t* d = depth.rowPtr(y);
    std::uint8_t* c = confidence.rowPtr(y);
    for (int x = 0; x < depth.width(); ++x) {
      const bool keep =
          d[x] >= window.minUnits && d[x] <= window.maxUnits && c[x] >= window.minConfidence;
      d[x] = keep ? d[x] : std::uint16_t{0};
      c[x] = keep ? c[x] : std::uint8_t{0};
    }
  }
}

}  // namespace smx::algo
