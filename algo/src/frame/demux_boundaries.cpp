// Stage 5: boundary detection and classification.
//   Response n (per channel, Q4.11): first-order pixels the separated value itself; second-order
//   pixels the difference of the separated values one pixel before and after along the
//   encoding direction (bilinear, Q8 positions), which peaks where the second derivative
//   crosses zero, with the sign of the step like a first derivative.
//   Strength = max_c n − min_c n (uint16, saturated). A boundary is a strength maximum along the
//   encoding direction (>= the sample one pixel ahead, > the one behind) above minStrength; its
//   sub-pixel offset is the vertex of the parabola through the three samples (±½ px, Q8).
//   Class: the rising channel is the colour after the boundary, the falling one the colour
//   before. Confidence 255 · (1 − |2·n_third − n_to − n_from| / (n_to − n_from)).
#include <algorithm>
#include <cstdint>

#include "demux_kernels.hpp"

namespace smx::algo::demux {

namespace {

// Bilinear sample at (xq, yq) in 1/256 pixel; the 2×2 neighbourhood must lie inside the plane.
template <class T>
std::int32_t sampleQ8(const ImageView<T>& plane, std::int32_t xq, std::int32_t yq) {
  const std::int32_t x0 = xq >> 8;
  const std::int32_t y0 = yq >> 8;
  const std::int32_t fx = xq & 255;
  const std::int32_t fy = yq & 255;
  const T* r0 = plane.rowPtr(y0);
  const T* r1 = plane.rowPtr(y0 + 1);
  const std::int32_t top = r0[x0] * (256 - fx) + r0[x0 + 1] * fx;
  const std::int32_t bottom = r1[x0] * (256 - fx) + r1[x0 + 1] * fx;
  return (top * (256 - fy) + bottom * fy + 32768) >> 16;
}

struct Response {
  std::int32_t n[3];
};

Response responseAt(const Planes3& separated, std::uint8_t order, int x, int y, std::int32_t ux,
                    std::int32_t uy) {
  Response r{};
  if (order == 1) {
    for (std::size_t c = 0; c < 3; ++c) {
      r.n[c] = separated[c].rowPtr(y)[x];
    }
    return r;
  }
  // ±1 px along the unit vector (Q1.14 → Q8: >> 6).
  const std::int32_t dx = ux >> 6;
  const std::int32_t dy = uy >> 6;
  const std::int32_t xq = x * 256;
  const std::int32_t yq = y * 256;
  for (std::size_t c = 0; c < 3; ++c) {
    r.n[c] = sampleQ8(separated[c], xq - dx, yq - dy) - sampleQ8(separated[c], xq + dx, yq + dy);
  }
  return r;
}

std::int32_t strengthOf(const Response& r) {
  std::int32_t hi = r.n[0];
  std::int32_t lo = r.n[0];
  for (const std::int32_t v : r.n) {
    hi = v > hi ? v : hi;
    lo = v < lo ? v : lo;
  }
  return hi - lo;
}

Boundary classify(const Response& r) {
  int to = 0;
  int from = 0;
  for (int c = 1; c < 3; ++c) {
    to = r.n[c] > r.n[to] ? c : to;
    from = r.n[c] < r.n[from] ? c : from;
  }
  const int third = 3 - to - from;
  const std::int32_t range = r.n[to] - r.n[from];
  std::int32_t dev = 2 * r.n[third] - r.n[to] - r.n[from];
  dev = dev < 0 ? -dev : dev;
  Boundary b;
  b.transition = Boundary::code(
      stripe::transitionBetween(stripe::colourFromIndex(from), stripe::colourFromIndex(to)));
  const std::int32_t conf = range > 0 ? (255 * (range - dev)) / range : 0;
  b.confidence = static_cast<std::uint8_t>(conf < 0 ? 0 : (conf > 255 ? 255 : conf));
  return b;
}

// Second order: the boundary is where the second derivative, read as (to − from) channel,
// crosses zero from + to − along the direction; linear between the samples at −1, 0, +1 px.
// Falls back to `fallback` when it does not cross there.
std::int32_t zeroCrossingQ8(const Planes3& separated, const Boundary& b, int x, int y,
                            std::int32_t ux, std::int32_t uy, std::int32_t fallback) {
  const auto to = static_cast<std::size_t>(stripe::indexOf(stripe::to(b.kind())));
  const auto from = static_cast<std::size_t>(stripe::indexOf(stripe::from(b.kind())));
  const std::int32_t xq = x * 256;
  const std::int32_t yq = y * 256;
  const auto v = [&](std::int32_t sx, std::int32_t sy) {
    return sampleQ8(separated[to], sx, sy) - sampleQ8(separated[from], sx, sy);
  };
  const std::int32_t before = v(xq - (ux >> 6), yq - (uy >> 6));
  const std::int32_t here = v(xq, yq);
  const std::int32_t after = v(xq + (ux >> 6), yq + (uy >> 6));
  if (here >= 0 && after < 0) {
    return (256 * here) / (here - after);
  }
  if (before > 0 && here < 0) {
    return -256 + (256 * before) / (before - here);
  }
  return fallback;
}

}  // namespace

void detectBoundaries(const Planes3& separated, ImageView<const std::uint8_t> order,
                      ConstDirectionPlane direction, const UnitTable& units, int minStrength,
                      ImageView<std::uint16_t> strength, BoundaryPlane out) {
  const int w = separated[0].width();
  const int h = separated[0].height();
  constexpr int kMargin = 3;  // responses and their neighbours stay inside the separated area

  for (int y = 0; y < h; ++y) {
    std::uint16_t* s = strength.rowPtr(y);
    for (int x = 0; x < w; ++x) {
      s[x] = 0;
    }
    if (y < kMargin || y >= h - kMargin) {
      continue;
    }
    const std::uint8_t* o = order.rowPtr(y);
    const std::uint16_t* d = direction.rowPtr(y);
    const std::int16_t* v0 = separated[0].rowPtr(y);
    const std::int16_t* v1 = separated[1].rowPtr(y);
    const std::int16_t* v2 = separated[2].rowPtr(y);
    // First-order pixels (most): max − min of the three planes, a branch-free loop; the
    // second-order ones are then redone with their bilinear responses.
    bool anySecond = false;
    for (int x = kMargin; x < w - kMargin; ++x) {
      const std::int32_t hi =
          std::max({std::int32_t{v0[x]}, std::int32_t{v1[x]}, std::int32_t{v2[x]}});
      const std::int32_t lo =
          std::min({std::int32_t{v0[x]}, std::int32_t{v1[x]}, std::int32_t{v2[x]}});
      s[x] = o[x] == 1 ? static_cast<std::uint16_t>(hi - lo > 65535 ? 65535 : hi - lo) : 0;
      anySecond = anySecond || o[x] == 2;
    }
    if (!anySecond) {
      continue;
    }
    for (int x = kMargin; x < w - kMargin; ++x) {
      if (o[x] == 2) {
        const std::int32_t v =
            strengthOf(responseAt(separated, 2, x, y, units.cosOf(d[x]), units.sinOf(d[x])));
        s[x] = static_cast<std::uint16_t>(v > 65535 ? 65535 : v);
      }
    }
  }

  const ImageView<const std::uint16_t> st = strength;
  for (int y = 0; y < h; ++y) {
    Boundary* b = out.rowPtr(y);
    const std::uint16_t* s = st.rowPtr(y);
    const std::uint8_t* o = order.rowPtr(y);
    const std::uint16_t* d = direction.rowPtr(y);
    for (int x = 0; x < w; ++x) {
      b[x] = Boundary{};
      const std::int32_t s0 = s[x];
      if (s0 < minStrength || y < kMargin + 1 || y >= h - kMargin - 1 || x < kMargin + 1 ||
          x >= w - kMargin - 1) {
        continue;
      }
      const std::int32_t ux = units.cosOf(d[x]);
      const std::int32_t uy = units.sinOf(d[x]);
      const std::int32_t xq = x * 256;
      const std::int32_t yq = y * 256;
      const std::int32_t ahead = sampleQ8(st, xq + (ux >> 6), yq + (uy >> 6));
      const std::int32_t behind = sampleQ8(st, xq - (ux >> 6), yq - (uy >> 6));
      if (s0 < ahead || s0 <= behind) {
        continue;
      }
      // A second-order response has side lobes of about half the peak two pixels out, with the
      // reversed class: such a maximum must also beat the samples two pixels away.
      if (o[x] == 2 && y >= kMargin + 2 && y < h - kMargin - 2 && x >= kMargin + 2 &&
          x < w - kMargin - 2 &&
          (s0 < sampleQ8(st, xq + (ux >> 5), yq + (uy >> 5)) ||
           s0 <= sampleQ8(st, xq - (ux >> 5), yq - (uy >> 5)))) {
        continue;
      }
      const std::int32_t den = ahead + behind - 2 * s0;  // < 0 at a strict maximum
      const std::int32_t parabola = den < 0 ? (128 * (behind - ahead)) / den : 0;
      Boundary found = classify(responseAt(separated, o[x], x, y, ux, uy));
      const std::int32_t offset =
          o[x] == 2 ? zeroCrossingQ8(separated, found, x, y, ux, uy, parabola) : parabola;
      found.offset = static_cast<std::int16_t>(std::clamp(offset, -128, 128));
      b[x] = found;
    }
  }
}

}  // namespace smx::algo::demux
