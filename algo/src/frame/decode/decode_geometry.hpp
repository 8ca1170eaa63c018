#pragma once

// The decoder's shared geometry (stripe_decode.hpp): Q8 positions, Q1.14 unit vectors and packed
// pixel links. Internal to src/frame (stripe_decode.cpp).

#include <cstddef>
#include <cstdint>

#include "demux_kernels.hpp"

namespace smx::algo::decode {

inline constexpr std::int32_t kNone = -1;

struct PointQ8 {
  std::int32_t x;
  std::int32_t y;
};

struct Unit {
  std::int32_t x;  // Q1.14
  std::int32_t y;
};

inline Unit unitOf(const demux::UnitTable& units, std::uint16_t angle) {
  return {units.cosOf(angle), units.sinOf(angle)};
}

// (to − from) · u in Q8 pixels.
inline std::int32_t along(PointQ8 from, PointQ8 to, Unit u) {
  const std::int64_t dot = std::int64_t{to.x - from.x} * u.x + std::int64_t{to.y - from.y} * u.y;
  return static_cast<std::int32_t>(dot >> 14);
}

// Index of (x, y) in the decoder's unpadded per-pixel planes.
constexpr std::size_t flat(int x, int y, int width) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
         static_cast<std::size_t>(x);
}

constexpr std::int32_t pack(int x, int y) {
  return (y << 16) | x;
}
constexpr int packedX(std::int32_t p) {
  return p & 0xFFFF;
}
constexpr int packedY(std::int32_t p) {
  return p >> 16;
}

}  // namespace smx::algo::decode
