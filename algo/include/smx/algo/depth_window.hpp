#pragma once

#include <cstdint>

#include "smx/algo/image_view.hpp"
#include "smx/algo/range_image.hpp"

// The owner's limits on what a range image may hold (docs/config.md): depths outside
// [minUnits, maxUnits] and depths whose confidence is below minConfidence become "no depth"
// (0, with confidence 0). Per frame: integer-only, allocation-free.
namespace smx::algo {

struct DepthWindow {
  std::uint16_t minUnits = 1;
  std::uint16_t maxUnits = 65535;
  std::uint8_t minConfidence = 1;

  // The window that keeps every depth: applying it changes nothing.
  [[nodiscard]] bool keepsAll() const {
    return minUnits <= 1 && maxUnits == 65535 && minConfidence <= 1;
  }
};

// Clears, in place, every pixel of `depth` (and `confidence`, the same size) outside the window.
void applyDepthWindow(DepthPlane depth, ImageView<std::uint8_t> confidence,
                      const DepthWindow& window);

}  // namespace smx::algo
