#include "smx/algo/stripe_code.hpp"

namespace smx::algo::stripe {

int decodeWindow(std::span<const Transition, kWindowTransitions> boundaries) {
  int bits = 0;
  for (int j = 0; j < kWindowTransitions; ++j) {
    const auto t = boundaries[static_cast<std::size_t>(j)];
    if (j > 0 && from(t) != to(boundaries[static_cast<std::size_t>(j - 1)])) {
      return -1;
    }
    if (isPlus(t)) {
      bits |= 1 << j;
    }
  }
  return kWindowIndex[static_cast<std::size_t>(windowCode(from(boundaries[0]), bits))];
}

int decodeWindow(std::span<const Colour, kWindowStripes> colours) {
  int bits = 0;
  for (int j = 0; j < kWindowTransitions; ++j) {
    const int a = indexOf(colours[static_cast<std::size_t>(j)]);
    const int b = indexOf(colours[static_cast<std::size_t>(j + 1)]);
    if (a == b || a >= kColours || b >= kColours) {
      return -1;
    }
    if ((a + 1) % kColours == b) {
      bits |= 1 << j;
    }
  }
  return kWindowIndex[static_cast<std::size_t>(windowCode(colours[0], bits))];
}

}  // namespace smx::algo::stripe
