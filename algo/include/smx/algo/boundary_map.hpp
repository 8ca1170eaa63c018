#pragma once

#include <cstdint>

#include "smx/algo/image_view.hpp"
#include "smx/algo/stripe_code.hpp"

// What orientation demultiplexing hands to the decoder, per projector and camera pixel: the
// stripe boundaries of that projector's pattern, found in the superposed image (paper §3, §4.2).
namespace smx::algo {

// A stripe boundary of one projector's pattern at a camera pixel. The boundary lies at the pixel
// centre + offset / 256 pixels along the projector's encoding direction at that pixel (the
// direction plane below), i.e. |offset| <= 128. transition is 0 where the pixel holds no
// boundary, else 1 + stripe::Transition read along +encoding direction (from-colour → to-colour).
// confidence: 0 (a guess) … 255 (a clean class).
struct Boundary {
  std::int16_t offset = 0;
  std::uint8_t transition = 0;
  std::uint8_t confidence = 0;

  static constexpr std::int16_t kOffsetOne = 256;  // one pixel

  [[nodiscard]] constexpr bool present() const { return transition != 0; }
  [[nodiscard]] constexpr stripe::Transition kind() const {
    return static_cast<stripe::Transition>(transition - 1);
  }
  [[nodiscard]] static constexpr std::uint8_t code(stripe::Transition t) {
    return static_cast<std::uint8_t>(static_cast<int>(t) + 1);
  }
};
static_assert(sizeof(Boundary) == 4);

using BoundaryPlane = ImageView<Boundary>;
using ConstBoundaryPlane = ImageView<const Boundary>;

// The encoding direction (+axis, towards growing stripe index) of one projector's pattern at
// each camera pixel, as the raw value of a BinAngle (65536 per turn; 0 = +x, 16384 = +y, image
// coordinates: x right, y down).
using DirectionPlane = ImageView<std::uint16_t>;
using ConstDirectionPlane = ImageView<const std::uint16_t>;

}  // namespace smx::algo
