#include "smx/algo/stripe_code.hpp"

namespace smx::algo::stripe {

int decodeWindow(std::span<const Transition, kWindowTransitions> boundaries) {
  int bits = 0;
  for (std::size_t j = 0; j < boundaries.size(); ++j) {
    const auto t = boundaries[j];
    if (j > 0 && from(t) != to(boundaries[j - 1])) {
      return -1;
    }
    if (isPlus(t)) {
      bits |= 1 << j;
    }
  }
  const int code = windowCode(from(boundaries[0]), bits);
  return kWindowIndex[static_cast<std::size_t>(code)];
}

int decodeWindow(std::span<const Colour, kWindowStripes> colours) {
  int bits = 0;
  for (std::size_t j = 0; j + 1 < colours.size(); ++j) {
    const int a = indexOf(colours[j]);
    const int b = indexOf(colours[j + 1]);
    if (a == b || a >= kColours || b >= kColours) {
      return -1;
    }
    if ((a + 1) % kColours == b) {
      bits |= 1 << j;
    }
  }
  const int code = windowCode(colours[0], bits);
  return kWindowIndex[static_cast<std::size_t>(code)];
}

}  // namespace smx::algo::stripe
