#pragma once

// The decoder's shared geometry (stripe_decode.hpp): Q8 positions, Q1.14 unit vectors, pixel
// links and the half-pixel walk along an axis, with the walks its schedules take. Internal
// to src/frame (stripe_decode.cpp).

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

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

// A walk's result: the boundary pixel it stopped at (its index y · width + x), or kNone, and where
// that boundary lies along the walk (Q8).
struct Hit {
  std::int32_t at;
  std::int32_t distance;
};

// The block at (x0, y0) of the walk: its nearest accepted boundary pixel, or kNone.
template <class Distance>
Hit nearestInBlock(std::span<const std::uint8_t> code, int width, int height, int x0, int y0,
                   Distance& distance) {
  std::int32_t best = kNone;
  std::int32_t bestDistance = 0;
  for (int qy = y0; qy <= y0 + 1; ++qy) {
    for (int qx = x0; qx <= x0 + 1; ++qx) {
      if (qx < 0 || qy < 0 || qx >= width || qy >= height) {
        continue;
      }
      const std::int32_t i = qy * width + qx;
      if (code[static_cast<std::size_t>(i)] == 0) {
        continue;
      }
      const std::int32_t dist = distance(qx, qy, i);
      if (dist >= 0 && (best == kNone || dist < bestDistance)) {
        best = i;
        bestDistance = dist;
      }
    }
  }
  return {best, bestDistance};
}

// The same for a block inside the image, whose first byte is at `p` (index i of (x0, y0)).
template <class Distance>
Hit nearestInInnerBlock(const std::uint8_t* p, std::size_t width, int x0, int y0, std::int32_t i,
                        Distance& distance) {
  std::int32_t best = kNone;
  std::int32_t bestDistance = 0;
  const auto w = static_cast<std::int32_t>(width);
  const auto look = [&](std::uint8_t code, int qx, int qy, std::int32_t q) {
    if (code == 0) {
      return;
    }
    const std::int32_t dist = distance(qx, qy, q);
    if (dist >= 0 && (best == kNone || dist < bestDistance)) {
      best = q;
      bestDistance = dist;
    }
  };
  look(p[0], x0, y0, i);
  look(p[1], x0 + 1, y0, i + 1);
  look(p[width], x0, y0 + 1, i + w);
  look(p[width + 1], x0 + 1, y0 + 1, i + w + 1);
  return {best, bestDistance};
}

// nearestInInnerBlock, passing over an empty block with two 2-byte loads: most blocks of a walk
// hold no boundary.
template <class Distance>
Hit lookInInnerBlock(const std::uint8_t* p, std::size_t width, int x0, int y0, std::int32_t i,
                     Distance& distance) {
  std::uint16_t top = 0;
  std::uint16_t bottom = 0;
  std::memcpy(&top, p, sizeof top);
  std::memcpy(&bottom, p + width, sizeof bottom);
  if ((top | bottom) == 0) {
    return {kNone, 0};
  }
  return nearestInInnerBlock(p, width, x0, y0, i, distance);
}

// The plain walk (the reference): half-pixel steps from `start` along (sx, sy) (Q8 per step),
// steps first…last; at each step the 2×2 pixels around the sample are looked at (a 1-pixel-thick
// oblique curve can pass between nearest-pixel samples), each 2×2 block once. `distance(x, y, i)`
// returns where the boundary at that pixel lies along the walk (Q8), or −1 to pass it over; the
// nearest accepted pixel of the first block that has one wins, else kNone.
template <class Distance>
Hit walk(std::span<const std::uint8_t> code, int width, int height, PointQ8 start, std::int32_t sx,
         std::int32_t sy, int first, int last, Distance distance) {
  int lastX0 = -2;
  int lastY0 = -2;
  for (int k = first; k <= last; ++k) {
    const int x0 = (start.x + k * sx) >> 8;
    const int y0 = (start.y + k * sy) >> 8;
    if (x0 < -1 || y0 < -1 || x0 >= width || y0 >= height) {
      return {kNone, 0};
    }
    if (x0 == lastX0 && y0 == lastY0) {
      continue;
    }
    lastX0 = x0;
    lastY0 = y0;
    const Hit hit = nearestInBlock(code, width, height, x0, y0, distance);
    if (hit.at != kNone) {
      return hit;
    }
  }
  return {kNone, 0};
}

// The same walk (the same blocks in the same order, the same hit), faster: when its first and
// last blocks lie inside the image, so do all between (the steps are monotone), and each block
// is looked at without bounds checks. Other walks take the plain one.
template <class Distance>
Hit walkSkippingEmpty(std::span<const std::uint8_t> code, int width, int height, PointQ8 start,
                      std::int32_t sx, std::int32_t sy, int first, int last, Distance distance) {
  const auto inside = [width, height](std::int32_t qx, std::int32_t qy) {
    return (qx >> 8) >= 0 && (qy >> 8) >= 0 && (qx >> 8) + 1 < width && (qy >> 8) + 1 < height;
  };
  std::int32_t px = start.x + first * sx;
  std::int32_t py = start.y + first * sy;
  if (!inside(px, py) || !inside(start.x + last * sx, start.y + last * sy)) {
    return walk(code, width, height, start, sx, sy, first, last, distance);
  }
  const std::uint8_t* base = code.data();
  const auto w = static_cast<std::size_t>(width);
  std::size_t lastBlock = ~std::size_t{0};
  for (int k = first; k <= last; ++k, px += sx, py += sy) {
    const std::size_t block = flat(px >> 8, py >> 8, width);
    if (block == lastBlock) {
      continue;
    }
    lastBlock = block;
    const Hit hit = lookInInnerBlock(base + block, w, px >> 8, py >> 8,
                                     static_cast<std::int32_t>(block), distance);
    if (hit.at != kNone) {
      return hit;
    }
  }
  return {kNone, 0};
}

}  // namespace smx::algo::decode
