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

// A bilinear sample point at a Q8 offset (dxq, dyq) from a whole pixel (x, y). Because the
// pixel's own position is whole, the offset alone fixes the 2×2 neighbourhood's corner relative
// to the pixel ((256·x + dxq) >> 8 = x + (dxq >> 8)) and the fractions ((256·x + dxq) & 255 =
// dxq & 255): one tap serves all three channels and the strength plane at the same offset.
struct TapQ8 {
  int dx;
  int dy;
  std::int32_t fx;
  std::int32_t fy;
};

constexpr TapQ8 tapQ8(std::int32_t dxq, std::int32_t dyq) {
  return {dxq >> 8, dyq >> 8, dxq & 255, dyq & 255};
}

// The bilinear sample at pixel + tap, where `pixel` points at (x, y) and stride is the row
// stride in pixels; the 2×2 neighbourhood must lie inside the plane. Arithmetic as the Q8
// sampler always had it: two horizontal blends, a vertical one, rounded half up.
template <class T>
std::int32_t sampleAt(const T* pixel, std::ptrdiff_t stride, const TapQ8& tap) {
  const T* r0 = pixel + static_cast<std::ptrdiff_t>(tap.dy) * stride + tap.dx;
  const T* r1 = r0 + stride;
  const std::int32_t top = r0[0] * (256 - tap.fx) + r0[1] * tap.fx;
  const std::int32_t bottom = r1[0] * (256 - tap.fx) + r1[1] * tap.fx;
  return (top * (256 - tap.fy) + bottom * tap.fy + 32768) >> 16;
}

template <class T>
std::ptrdiff_t strideOf(const ImageView<T>& plane) {
  return plane.strideBytes() / static_cast<std::ptrdiff_t>(sizeof(T));
}

// The taps one pixel behind and ahead along the unit vector (Q1.14 → Q8: >> 6), or two pixels
// (>> 5).
struct TapPair {
  TapQ8 behind;
  TapQ8 ahead;
};

TapPair tapsAlong(std::int32_t ux, std::int32_t uy, int shift) {
  const std::int32_t dx = ux >> shift;
  const std::int32_t dy = uy >> shift;
  return {tapQ8(-dx, -dy), tapQ8(dx, dy)};
}

struct Response {
  std::int32_t n[3];
};

// One row of the three separated planes: the per-channel row pointers and strides, looked up
// once per row instead of once per sample.
class SeparatedRow {
 public:
  SeparatedRow(const Planes3& separated, int y) {
    for (std::size_t c = 0; c < 3; ++c) {
      row_[c] = separated[c].rowPtr(y);
      stride_[c] = strideOf(separated[c]);
    }
  }

  // The three channels' bilinear samples at (x, y) + tap.
  [[nodiscard]] Response samples(int x, const TapQ8& tap) const {
    Response r{};
    for (std::size_t c = 0; c < 3; ++c) {
      r.n[c] = sampleAt(row_[c] + x, stride_[c], tap);
    }
    return r;
  }
  [[nodiscard]] std::int32_t value(std::size_t c, int x) const { return row_[c][x]; }

 private:
  const std::int16_t* row_[3] = {};
  std::ptrdiff_t stride_[3] = {};
};

// Second order: the difference of the separated values one pixel behind and ahead along the
// encoding direction, per channel.
Response secondOrderResponse(const Response& behind, const Response& ahead) {
  Response r{};
  for (std::size_t c = 0; c < 3; ++c) {
    r.n[c] = behind.n[c] - ahead.n[c];
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

std::uint16_t saturateStrength(std::int32_t v) {
  return static_cast<std::uint16_t>(v > 65535 ? 65535 : v);
}

Boundary classify(const Response& r) {
  int to = 0;
  int from = 0;
  for (int c = 1; c < 3; ++c) {
    to = r.n[c] > r.n[to] ? c : to;
    from = r.n[c] < r.n[from] ? c : from;
  }
  const std::int32_t range = r.n[to] - r.n[from];
  Boundary b;
  b.transition = Boundary::code(
      stripe::transitionBetween(stripe::colourFromIndex(from), stripe::colourFromIndex(to)));
  std::int32_t conf = 0;
  if (to != from) {  // not all equal: range > 0, and the third channel is the remaining one
    const int third = 3 - to - from;
    std::int32_t dev = 2 * r.n[third] - r.n[to] - r.n[from];
    dev = dev < 0 ? -dev : dev;
    conf = (255 * (range - dev)) / range;
  }
  b.confidence = static_cast<std::uint8_t>(conf < 0 ? 0 : (conf > 255 ? 255 : conf));
  return b;
}

// Second order: the boundary is where the second derivative, read as (to − from) channel,
// crosses zero from + to − along the direction; linear between the samples at −1, 0, +1 px,
// which are the response's own samples (behind, ahead) and the pixel itself (a bilinear sample
// at a whole position is the pixel's value). Falls back to `fallback` when it does not cross there.
std::int32_t zeroCrossingQ8(const SeparatedRow& row, const Boundary& b, int x,
                            const Response& behindSamples, const Response& aheadSamples,
                            std::int32_t fallback) {
  const auto to = static_cast<std::size_t>(stripe::indexOf(stripe::to(b.kind())));
  const auto from = static_cast<std::size_t>(stripe::indexOf(stripe::from(b.kind())));
  const std::int32_t before = behindSamples.n[to] - behindSamples.n[from];
  const std::int32_t here = row.value(to, x) - row.value(from, x);
  const std::int32_t after = aheadSamples.n[to] - aheadSamples.n[from];
  if (here >= 0 && after < 0) {
    return (256 * here) / (here - after);
  }
  if (before > 0 && here < 0) {
    return -256 + (256 * before) / (before - here);
  }
  return fallback;
}

}  // namespace

namespace {

constexpr int kMargin = 3;    // responses and their neighbours stay inside the separated area
constexpr int kChunkPx = 64;  // non-maximum suppression: pixels tested before the candidates

// One row of the strength plane: max − min over the channels of the response, 0 in the margin.
void strengthRow(const Planes3& separated, ImageView<const std::uint8_t> order,
                 ConstDirectionPlane direction, const UnitTable& units, int y, std::uint16_t* s) {
  const int w = separated[0].width();
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
    s[x] = o[x] == 1 ? saturateStrength(hi - lo) : 0;
    anySecond = anySecond || o[x] == 2;
  }
  if (!anySecond) {
    return;
  }
  const SeparatedRow row(separated, y);
  for (int x = kMargin; x < w - kMargin; ++x) {
    if (o[x] == 2) {
      const TapPair taps = tapsAlong(units.cosOf(d[x]), units.sinOf(d[x]), 6);
      s[x] = saturateStrength(
          strengthOf(secondOrderResponse(row.samples(x, taps.behind), row.samples(x, taps.ahead))));
    }
  }
}

// Where the strength at x is at least the minimum and no less than the bilinear sample one pixel
// ahead along the encoding direction and more than the one behind.
struct Candidate {
  int x;
  std::int32_t ahead;
  std::int32_t behind;
};

// The maxima of one row chunk [x0, x1) into `found`; returns their count. Whether a pixel is a
// maximum is unpredictable, so every pixel takes both samples and is appended branch-free (the
// sample positions are inside the plane whatever the strength); the costly rest of the test
// runs on the candidates only.
int maximaAlong(ImageView<const std::uint16_t> st, const std::uint16_t* d, const UnitTable& units,
                int minStrength, int y, int x0, int x1, Candidate* found) {
  const std::ptrdiff_t stride = strideOf(st);
  const std::uint16_t* s = st.rowPtr(y);
  int count = 0;
  for (int x = x0; x < x1; ++x) {
    const TapPair taps = tapsAlong(units.cosOf(d[x]), units.sinOf(d[x]), 6);
    const std::int32_t s0 = s[x];
    const std::int32_t ahead = sampleAt(s + x, stride, taps.ahead);
    const std::int32_t behind = sampleAt(s + x, stride, taps.behind);
    found[count] = {x, ahead, behind};
    // Bitwise, not short-circuit: no branch to mispredict.
    count += static_cast<int>(s0 >= minStrength) & static_cast<int>(s0 >= ahead) &
             static_cast<int>(s0 > behind);
  }
  return count;
}

// The boundary at a candidate maximum (x, y) of strength s0, or none when it is a side lobe.
Boundary boundaryAt(const SeparatedRow& row, ImageView<const std::uint16_t> st, std::uint8_t order,
                    std::int32_t ux, std::int32_t uy, int y, const Candidate& c) {
  const int w = st.width();
  const int h = st.height();
  const int x = c.x;
  const std::uint16_t* here = st.rowPtr(y) + x;
  const std::int32_t s0 = *here;
  // A second-order response has side lobes of about half the peak two pixels out, with the
  // reversed class: such a maximum must also beat the samples two pixels away.
  if (order == 2 && y >= kMargin + 2 && y < h - kMargin - 2 && x >= kMargin + 2 &&
      x < w - kMargin - 2) {
    const std::ptrdiff_t stride = strideOf(st);
    const TapPair far = tapsAlong(ux, uy, 5);
    if (s0 < sampleAt(here, stride, far.ahead) || s0 <= sampleAt(here, stride, far.behind)) {
      return {};
    }
  }
  const std::int32_t den = c.ahead + c.behind - 2 * s0;  // < 0 at a strict maximum
  const std::int32_t parabola = den < 0 ? (128 * (c.behind - c.ahead)) / den : 0;
  std::int32_t offset = parabola;
  Boundary found;
  if (order == 1) {
    found = classify({{row.value(0, x), row.value(1, x), row.value(2, x)}});
  } else {
    const TapPair taps = tapsAlong(ux, uy, 6);
    const Response behindSamples = row.samples(x, taps.behind);
    const Response aheadSamples = row.samples(x, taps.ahead);
    found = classify(secondOrderResponse(behindSamples, aheadSamples));
    if (order == 2) {
      offset = zeroCrossingQ8(row, found, x, behindSamples, aheadSamples, parabola);
    }
  }
  found.offset = static_cast<std::int16_t>(std::clamp(offset, -128, 128));
  return found;
}

}  // namespace

void detectBoundaries(const Planes3& separated, ImageView<const std::uint8_t> order,
                      ConstDirectionPlane direction, const UnitTable& units, int minStrength,
                      ImageView<std::uint16_t> strength, BoundaryPlane out) {
  const int w = separated[0].width();
  const int h = separated[0].height();

  for (int y = 0; y < h; ++y) {
    std::uint16_t* s = strength.rowPtr(y);
    for (int x = 0; x < w; ++x) {
      s[x] = 0;
    }
    if (y >= kMargin && y < h - kMargin) {
      strengthRow(separated, order, direction, units, y, s);
    }
  }

  // Non-maximum suppression, one pixel inside the margin (its samples stay in the strength
  // plane's computed area).
  const ImageView<const std::uint16_t> st = strength;
  for (int y = 0; y < h; ++y) {
    Boundary* b = out.rowPtr(y);
    for (int x = 0; x < w; ++x) {
      b[x] = Boundary{};
    }
    if (y < kMargin + 1 || y >= h - kMargin - 1) {
      continue;
    }
    const std::uint8_t* o = order.rowPtr(y);
    const std::uint16_t* d = direction.rowPtr(y);
    const SeparatedRow row(separated, y);
    for (int x0 = kMargin + 1; x0 < w - kMargin - 1; x0 += kChunkPx) {
      const int x1 = std::min(x0 + kChunkPx, w - kMargin - 1);
      Candidate candidates[kChunkPx];
      const int count = maximaAlong(st, d, units, minStrength, y, x0, x1, candidates);
      for (int i = 0; i < count; ++i) {
        const int x = candidates[i].x;
        b[x] = boundaryAt(row, st, o[x], units.cosOf(d[x]), units.sinOf(d[x]), y, candidates[i]);
      }
    }
  }
}

}  // namespace smx::algo::demux
