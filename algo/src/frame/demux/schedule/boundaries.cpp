// Stages 4–5, the schedule of detectBoundaries() (reference: reference/boundaries.cpp): division
// by the local colour, boundary detection and classification.
//   Relative value (per channel, Q4.11): a separated value D times the inverse colour of the
//   pixel examined (its nearest tile's average over the tile's window); the samples around a
//   pixel share its divisor. (Averages interpolated between tile centres gave the same
//   boundary figures but 0.3–0.6 % less decoded depth on the sphere and the cups.)
//   Response n: first-order pixels the relative value itself; second-order pixels the
//   difference of the relative values one pixel before and after along the encoding direction
//   (bilinear, Q8 positions), which peaks where the second derivative crosses zero, with the
//   sign of the step like a first derivative.
//   Strength = max_c n − min_c n (uint16, saturated). A boundary is a strength maximum along the
//   encoding direction (>= the sample one pixel ahead, > the one behind) above minStrength. Its
//   sub-pixel offset (±½ px, Q8): first order, the vertex of the parabola through max_c D −
//   min_c D at −1, 0, +1 px (the derivative itself, where the camera's noise is even); second
//   order, the zero crossing of the relative response.
//   Class: the rising channel is the colour after the boundary, the falling one the colour
//   before. Confidence 255 · (1 − |2·n_third − n_to − n_from| / (n_to − n_from)).
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>

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

// A row of the divisor per channel: the inverse colour (<= 2^24 / kColourFloor = 2^17) scaled
// into int16 (>> kScaleShift, rounded: <= 0.2 % off, far below the noise), and the largest |D|
// whose relative value fits int16.
constexpr int kScaleShift = 4;
struct InverseRow {
  std::int16_t* scale[3];
  std::int16_t* bound[3];
};

// D · scale >> kRelativeProductShift: Q4.11 relative to the average colour, D clamped to the
// bound first so that the result fits int16 (at most 16 below saturation). Since it fits, its
// 16 bits are the product's high half shifted up and low half shifted down: int16 operations
// only, the two halves being the vector units' native int16 products (SSE2 pmulhw and pmullw);
// written as one int32 product and a narrowing, GCC shuffles the halves together and apart.
constexpr int kRelativeProductShift = kInverseShift - kRelativeShift - kScaleShift;
std::int16_t relativeToColour(std::int16_t d, std::int16_t scale, std::int16_t bound) {
  const std::int16_t upper = d > bound ? bound : d;
  const auto lowest = static_cast<std::int16_t>(-bound);
  const std::int16_t clamped = upper < lowest ? lowest : upper;
  const auto high = static_cast<std::int16_t>((clamped * scale) >> 16);
  const auto low = static_cast<std::uint16_t>(static_cast<std::uint16_t>(clamped) *
                                              static_cast<std::uint16_t>(scale));
  return static_cast<std::int16_t>(
      static_cast<std::uint16_t>(high << (16 - kRelativeProductShift)) |
      static_cast<std::uint16_t>(low >> kRelativeProductShift));
}

// A tile row's divisor per pixel: its nearest tile's inverse colour (once per tile row).
void inverseColourRow(const TileColours& colours, int tileRow, const InverseRow& out) {
  const std::uint32_t* inverse =
      colours.inverse.data() +
      static_cast<std::size_t>(tileRow) * static_cast<std::size_t>(colours.tilesX) * 3;
  std::int16_t scale[3] = {};
  std::int16_t bound[3] = {};
  std::size_t lastTile = colours.columns.size() + 1;  // no tile: the first pixel sets them
  for (std::size_t x = 0; x < colours.columns.size(); ++x) {
    const auto tile = static_cast<std::size_t>(colours.columns[x].nearest);
    if (tile != lastTile) {  // runs of tilePx pixels
      lastTile = tile;
      for (std::size_t c = 0; c < 3; ++c) {
        constexpr std::uint32_t kRound = 1U << (kScaleShift - 1);
        const std::uint32_t scaled = (inverse[tile * 3 + c] + kRound) >> kScaleShift;
        constexpr std::uint32_t kLargest = 32767U << kRelativeProductShift;
        const std::uint32_t largest = kLargest / scaled;
        scale[c] = static_cast<std::int16_t>(scaled);
        bound[c] = static_cast<std::int16_t>(largest > 32767U ? 32767U : largest);
      }
    }
    for (std::size_t c = 0; c < 3; ++c) {
      out.scale[c][x] = scale[c];
      out.bound[c][x] = bound[c];
    }
  }
}

// Separated values (samples around pixel x) relative to the colour at x.
Response relativeAt(const InverseRow& inverse, const Response& d, int x) {
  Response r{};
  for (std::size_t c = 0; c < 3; ++c) {
    r.n[c] = relativeToColour(static_cast<std::int16_t>(d.n[c]), inverse.scale[c][x],
                              inverse.bound[c][x]);
  }
  return r;
}

// Second order: the difference of the separated values one pixel behind and ahead along the
// encoding direction, per channel.
Response secondOrderResponse(const Response& behind, const Response& ahead) {
  Response r{};
  for (std::size_t c = 0; c < 3; ++c) {
    r.n[c] = behind.n[c] - ahead.n[c];
  }
  return r;
}

// max − min of three int16 values, which fits uint16.
std::uint16_t spread(std::int16_t a, std::int16_t b, std::int16_t c) {
  return static_cast<std::uint16_t>(std::max({a, b, c}) - std::min({a, b, c}));
}

// The transition code (Boundary::code) from the falling channel f to the rising one t, at
// 3·f + t (f = t: none).
constexpr auto kTransitionCodes = [] {
  std::array<std::uint8_t, 9> codes{};
  for (int f = 0; f < 3; ++f) {
    for (int t = 0; t < 3; ++t) {
      codes[static_cast<std::size_t>(f) * 3 + static_cast<std::size_t>(t)] =
          f == t ? std::uint8_t{0}
                 : Boundary::code(stripe::transitionBetween(stripe::colourFromIndex(f),
                                                            stripe::colourFromIndex(t)));
    }
  }
  return codes;
}();

// The rising channel is the first largest, the falling one the first smallest; the third
// channel's value is the median (the sum less the largest and the smallest).
Boundary classify(const Response& r) {
  const std::int32_t a = r.n[0];
  const std::int32_t b = r.n[1];
  const std::int32_t c = r.n[2];
  const int to = b > a ? (c > b ? 2 : 1) : (c > a ? 2 : 0);
  const int from = b < a ? (c < b ? 2 : 1) : (c < a ? 2 : 0);
  const std::int32_t high = std::max({a, b, c});
  const std::int32_t low = std::min({a, b, c});
  const std::int32_t range = high - low;
  Boundary found;
  found.transition =
      kTransitionCodes[static_cast<std::size_t>(from) * 3 + static_cast<std::size_t>(to)];
  std::int32_t conf = 0;
  if (range > 0) {  // not all equal: the third channel is the remaining one
    std::int32_t dev = 2 * (a + b + c - high - low) - high - low;
    dev = dev < 0 ? -dev : dev;
    conf = (255 * (range - dev)) / range;
  }
  found.confidence = static_cast<std::uint8_t>(conf < 0 ? 0 : (conf > 255 ? 255 : conf));
  return found;
}

// Second order: the boundary is where the second derivative, read as (to − from) channel,
// crosses zero from + to − along the direction; linear between the samples at −1, 0, +1 px,
// which are the response's own samples (behind, ahead) and the pixel itself (a bilinear sample
// at a whole position is the pixel's value). None when it does not cross there.
std::optional<std::int32_t> zeroCrossingQ8(const Boundary& b, const Response& behindSamples,
                                           const Response& hereValues,
                                           const Response& aheadSamples) {
  const auto to = static_cast<std::size_t>(stripe::indexOf(stripe::to(b.kind())));
  const auto from = static_cast<std::size_t>(stripe::indexOf(stripe::from(b.kind())));
  const std::int32_t before = behindSamples.n[to] - behindSamples.n[from];
  const std::int32_t here = hereValues.n[to] - hereValues.n[from];
  const std::int32_t after = aheadSamples.n[to] - aheadSamples.n[from];
  if (here >= 0 && after < 0) {
    return (256 * here) / (here - after);
  }
  if (before > 0 && here < 0) {
    return -256 + (256 * before) / (before - here);
  }
  return std::nullopt;
}

// The vertex of the parabola through samples at −1, 0, +1 px (Q8), when the middle one is a
// strict maximum.
std::optional<std::int32_t> vertexQ8(std::int32_t behind, std::int32_t centre, std::int32_t ahead) {
  const std::int32_t den = ahead + behind - 2 * centre;
  if (den >= 0) {
    return std::nullopt;
  }
  return (128 * (behind - ahead)) / den;
}

}  // namespace

namespace {

constexpr int kMargin = 3;     // responses and their neighbours stay inside the separated area
constexpr int kChunkPx = 128;  // pixels per chunk of a row: taps, samples and maxima on the stack

// The second-order samples' taps one pixel behind and ahead along the encoding direction for a
// chunk of a row, as plain rows: per pixel the bilinear fractions in x and y, and a code of the
// four integer offsets. The direction field is smooth, so the code is constant over runs, and
// within a run every sample is shifted-row arithmetic in int16 lanes. (The tents below take
// the same arithmetic for every pixel, but blend16's rounding depends on which two values it
// blends: selecting them per pixel cost 15 % of the 3-projector stage.)
struct TapWeights {
  std::int16_t x1[kChunkPx];
  std::int16_t y1[kChunkPx];
};

struct ChunkTaps {
  TapWeights behind;
  TapWeights ahead;
  std::uint8_t offsets[kChunkPx];
};

// The integer offsets of the Q8 taps (behind dx, dy, ahead dx, dy), each in {−1, 0, 1}, two
// bits apiece.
constexpr std::uint8_t offsetCode(std::int16_t bx, std::int16_t by, std::int16_t ax,
                                  std::int16_t ay) {
  const auto part = [](std::int16_t q8) { return static_cast<std::uint8_t>((q8 >> 8) + 1); };
  return static_cast<std::uint8_t>(part(bx) | (part(by) << 2) | (part(ax) << 4) | (part(ay) << 6));
}

struct RunOffsets {
  int behindDx;
  int behindDy;
  int aheadDx;
  int aheadDy;
};

constexpr RunOffsets offsetsOf(std::uint8_t code) {
  return {(code & 3) - 1, ((code >> 2) & 3) - 1, ((code >> 4) & 3) - 1, ((code >> 6) & 3) - 1};
}

// The unit vector of each UnitTable entry in Q8 (Q1.14 >> 6), x in the low and y in the high
// half: one lookup per pixel instead of two; an angle's sine is the entry a quarter turn (256
// entries) before its cosine.
class UnitsQ8 {
 public:
  static constexpr std::size_t kEntries = UnitTable::kEntries;

  explicit UnitsQ8(const UnitTable& units) {
    for (std::size_t i = 0; i < kEntries; ++i) {
      const auto angle = static_cast<std::uint16_t>(i << 6U);
      const auto x = static_cast<std::uint16_t>(units.cosOf(angle) >> 6);
      const auto y = static_cast<std::uint16_t>(units.sinOf(angle) >> 6);
      q8_[i] = x | (std::uint32_t{y} << 16U);
    }
  }
  [[nodiscard]] std::uint32_t operator[](std::uint16_t entry) const { return q8_[entry]; }
  // The entry nearest a direction (BinAngle raw). 16-bit wrap-around: the carry out of the sum
  // is masked off by the entry count anyway.
  [[nodiscard]] static std::uint16_t entryOf(std::uint16_t direction) {
    const auto rounded = static_cast<std::uint16_t>(direction + 32U);
    return static_cast<std::uint16_t>((rounded >> 6U) & (kEntries - 1U));
  }

 private:
  std::array<std::uint32_t, kEntries> q8_{};
};

// The unit vectors (Q8) of a chunk's n pixels from the direction row d: UnitTable's entries,
// rounded to the nearest, by one gather.
struct ChunkUnits {
  std::int16_t ux[kChunkPx];  // [−256, 256]
  std::int16_t uy[kChunkPx];
};

void chunkUnits(const std::uint16_t* d, const UnitsQ8& units, int n, ChunkUnits& u) {
  std::uint32_t unit[kChunkPx];
  for (int i = 0; i < n; ++i) {
    unit[i] = units[UnitsQ8::entryOf(d[i])];
  }
  for (int i = 0; i < n; ++i) {
    u.ux[i] = static_cast<std::int16_t>(unit[i]);
    u.uy[i] = static_cast<std::int16_t>(unit[i] >> 16U);
  }
}

// The ±1 px taps (tapsAlong(…, 6)) of the chunk's pixels, in loops that vectorise.
void chunkTaps(const ChunkUnits& u, int n, ChunkTaps& t) {
  for (int i = 0; i < n; ++i) {
    const std::int16_t ax = u.ux[i];
    const std::int16_t ay = u.uy[i];
    t.ahead.x1[i] = static_cast<std::int16_t>(ax & 255);
    t.ahead.y1[i] = static_cast<std::int16_t>(ay & 255);
    t.behind.x1[i] = static_cast<std::int16_t>(-ax & 255);
    t.behind.y1[i] = static_cast<std::int16_t>(-ay & 255);
    t.offsets[i] =
        offsetCode(static_cast<std::int16_t>(-ax), static_cast<std::int16_t>(-ay), ax, ay);
  }
}

// Calls f(i0, i1, offsets) for each run of equal offsets in [0, n); mostly one run.
template <class F>
void forEachRun(const ChunkTaps& t, int n, F&& f) {
  if (n <= 0) {
    return;
  }
  unsigned differs = 0;
  for (int i = 0; i < n; ++i) {
    differs |= static_cast<unsigned>(t.offsets[i] ^ t.offsets[0]);
  }
  if (differs == 0) {
    f(0, n, offsetsOf(t.offsets[0]));
    return;
  }
  for (int i0 = 0; i0 < n;) {
    int i1 = i0 + 1;
    while (i1 < n && t.offsets[i1] == t.offsets[i0]) {
      ++i1;
    }
    f(i0, i1, offsetsOf(t.offsets[i0]));
    i0 = i1;
  }
}

template <class T>
const T* cornerOf(const T* pixel0, std::ptrdiff_t stride, int dx, int dy) {
  return pixel0 + static_cast<std::ptrdiff_t>(dy) * stride + dx;
}

// The bilinear samples one pixel ahead and behind along the encoding direction, for a chunk. A
// sample at a Q8 offset u in [−256, 256] along one axis is the tent over the columns −1, 0, +1
// with weights max(−u, 0), 256 − |u|, max(u, 0): the bilinear blend of the two columns around
// it whatever the sign of u, which is 256·v(0) + u·(v(1) − v(0)) for u > 0 and 256·v(0) +
// u·(v(0) − v(−1)) otherwise (the sample behind, at −u, takes the other difference). So every
// pixel takes the same arithmetic and the loops vectorise over whole chunks, where the 2×2
// corners' offsets split chunks into runs wherever a component of the direction changes sign.
// The sums are those of the bilinear blend's, exact in uint32 arithmetic: a sample is at most
// 65535 · 2^16 + 2^15 < 2^32 before the shift, so wrapping differences cancel.
struct TentRows {
  const std::uint16_t* above;
  const std::uint16_t* at;
  const std::uint16_t* below;
};

TentRows tentRows(const std::uint16_t* pixel0, std::ptrdiff_t stride) {
  return {pixel0 - stride, pixel0, pixel0 + stride};
}

struct TentPair {
  std::uint32_t ahead;  // 256 × the horizontal blend, or 2^16 × the bilinear sample
  std::uint32_t behind;
};

// The blends at ±u along one axis from the values at −1, 0, +1.
TentPair tentBlend(std::uint32_t minus, std::uint32_t centre, std::uint32_t plus, std::int32_t u) {
  const std::uint32_t forward = plus - centre;
  const std::uint32_t backward = centre - minus;
  const auto su = static_cast<std::uint32_t>(u);
  return {(centre << 8U) + su * (u > 0 ? forward : backward),
          (centre << 8U) - su * (u > 0 ? backward : forward)};
}

// The samples ahead and behind of pixel i of the chunk, rounded half up.
TentPair tentSamples(const TentRows& r, const ChunkUnits& u, int i) {
  const std::int32_t ux = u.ux[i];
  const TentPair above = tentBlend(r.above[i - 1], r.above[i], r.above[i + 1], ux);
  const TentPair at = tentBlend(r.at[i - 1], r.at[i], r.at[i + 1], ux);
  const TentPair below = tentBlend(r.below[i - 1], r.below[i], r.below[i + 1], ux);
  const std::int32_t uy = u.uy[i];
  const std::uint32_t ahead = tentBlend(above.ahead, at.ahead, below.ahead, uy).ahead;
  const std::uint32_t behind = tentBlend(above.behind, at.behind, below.behind, uy).behind;
  return {(ahead + 32768U) >> 16U, (behind + 32768U) >> 16U};
}

// (a·(256 − f) + b·f) / 256 for int16 a, b with |b − a| < 2^15 and f in [0, 255], in int16
// lanes: the product's high half (b − a)·(128·f) >> 16 is a native int16 vector multiply (SSE2
// pmulhw), where int32 products are emulated. Rounded down to even units: under 2 units of D
// (1/16 grey level per pixel) low, the same for every sample.
std::int16_t blend16(std::int16_t a, std::int16_t b, std::int16_t f) {
  const auto diff = static_cast<std::int16_t>(b - a);
  const auto f128 = static_cast<std::int16_t>(f << 7);
  const auto half = static_cast<std::int16_t>((diff * f128) >> 16);
  return static_cast<std::int16_t>(a + 2 * half);
}

// One channel's samples behind and ahead over a run (|D| < 2^14: differences fit int16).
void samplesRun(const std::int16_t* pixel0, std::ptrdiff_t stride, const ChunkTaps& t,
                const RunOffsets& o, int i0, int i1, std::int16_t* behind, std::int16_t* ahead) {
  const std::int16_t* b0 = cornerOf(pixel0, stride, o.behindDx, o.behindDy);
  const std::int16_t* b1 = b0 + stride;
  const std::int16_t* a0 = cornerOf(pixel0, stride, o.aheadDx, o.aheadDy);
  const std::int16_t* a1 = a0 + stride;
  for (int i = i0; i < i1; ++i) {
    const std::int16_t bx = t.behind.x1[i];
    const std::int16_t ax = t.ahead.x1[i];
    behind[i] =
        blend16(blend16(b0[i], b0[i + 1], bx), blend16(b1[i], b1[i + 1], bx), t.behind.y1[i]);
    ahead[i] = blend16(blend16(a0[i], a0[i + 1], ax), blend16(a1[i], a1[i + 1], ax), t.ahead.y1[i]);
  }
}

// The working rows: the second-order samples of D (behind per channel, then ahead per channel)
// and the relative values per channel of the last rows the strength pass computed, kept for the
// maxima found three rows later (row y's nine rows in slot y mod kBoundaryRingSlots), and the
// divisor of the last two tile rows (tile row t's six rows in slot t mod 2: the maxima trail the
// strength by fewer rows than a tile has).
class SampleRing {
 public:
  explicit SampleRing(const RowBlock<std::int16_t>& rows) : rows_(rows) {}

  // Sample j (0–5) of pixel x of row y.
  [[nodiscard]] std::int16_t* at(int y, int j, int x) const {
    const std::size_t slot = static_cast<std::size_t>(y) % kBoundaryRingSlots;
    return rows_.row(slot * kSlotRows + static_cast<std::size_t>(j)) + x;
  }
  // Channel c's relative value of pixel x of row y.
  [[nodiscard]] std::int16_t* relative(int y, int c, int x) const { return at(y, kSamples + c, x); }

  // Tile row t's divisor, from pixel x on.
  [[nodiscard]] InverseRow inverse(int tileRow, int x) const {
    const std::size_t first =
        kBoundaryRingSlots * kSlotRows + static_cast<std::size_t>(tileRow % 2) * 6;
    InverseRow r{};
    for (std::size_t c = 0; c < 3; ++c) {
      r.scale[c] = rows_.row(first + c) + x;
      r.bound[c] = rows_.row(first + 3 + c) + x;
    }
    return r;
  }

 private:
  static constexpr int kSamples = 6;
  static constexpr std::size_t kSlotRows = kSamples + 3;
  static_assert(kBoundaryRingRows == kBoundaryRingSlots * kSlotRows + std::size_t{2} * 6);
  RowBlock<std::int16_t> rows_;
};

// One chunk [x0, x0 + n) of the strength rows: max − min over the channels of the response,
// relative (s) and of the derivative itself (sd), where first-order pixels' response is the
// value and second-order ones' the bilinear difference; 0 where the order is 0.
void strengthChunk(const Planes3& separated, const std::uint8_t* o, const std::uint16_t* d,
                   const UnitsQ8& units, const SampleRing& ring, const InverseRow& inv, int y,
                   int x0, int n, std::uint16_t* s, std::uint16_t* sd) {
  const std::int16_t* v[3];
  for (std::size_t c = 0; c < 3; ++c) {
    v[c] = separated[c].rowPtr(y) + x0;
  }
  // ORs, not ||: the loops vectorise. Chunks are mostly of one order.
  unsigned anyFirst = 0;
  unsigned anySecond = 0;
  for (int i = 0; i < n; ++i) {
    anyFirst |= static_cast<unsigned>(o[i] == 1);
    anySecond |= static_cast<unsigned>(o[i] == 2);
  }
  // The pixels' relative values, which the boundaries found at them classify.
  std::int16_t* relative[3];
  for (int c = 0; c < 3; ++c) {
    relative[c] = ring.relative(y, c, x0);
  }
  if ((anyFirst | anySecond) != 0) {
    for (std::size_t c = 0; c < 3; ++c) {
      SMX_IVDEP
      for (int i = 0; i < n; ++i) {
        relative[c][i] = relativeToColour(v[c][i], inv.scale[c][i], inv.bound[c][i]);
      }
    }
  }
  if (anyFirst == 0) {
    std::fill_n(s, n, std::uint16_t{0});
    std::fill_n(sd, n, std::uint16_t{0});
  } else {
    SMX_IVDEP
    for (int i = 0; i < n; ++i) {
      const std::uint16_t r = spread(v[0][i], v[1][i], v[2][i]);  // unconditional: vectorises
      sd[i] = o[i] == 1 ? r : std::uint16_t{0};
    }
    SMX_IVDEP
    for (int i = 0; i < n; ++i) {
      const std::uint16_t r = spread(relative[0][i], relative[1][i], relative[2][i]);
      s[i] = o[i] == 1 ? r : std::uint16_t{0};
    }
  }
  if (anySecond == 0) {
    return;
  }
  ChunkUnits unitsQ8;  // NOLINT(cppcoreguidelines-pro-type-member-init): chunkUnits() fills it
  chunkUnits(d, units, n, unitsQ8);
  ChunkTaps taps;  // NOLINT(cppcoreguidelines-pro-type-member-init): chunkTaps() fills it
  chunkTaps(unitsQ8, n, taps);
  std::int16_t samples[6][kChunkPx];  // behind per channel, then ahead
  forEachRun(taps, n, [&](int i0, int i1, const RunOffsets& offsets) {
    for (std::size_t c = 0; c < 3; ++c) {
      samplesRun(v[c], strideOf(separated[c]), taps, offsets, i0, i1, samples[c], samples[3 + c]);
    }
  });
  // The response: per channel the difference (|D| < 2^14: it fits int16), then relative to the
  // colour. Simple loops, each of which vectorises.
  std::int16_t response[3][kChunkPx];
  for (std::size_t c = 0; c < 3; ++c) {
    for (int i = 0; i < n; ++i) {
      response[c][i] = static_cast<std::int16_t>(samples[c][i] - samples[3 + c][i]);
    }
  }
  for (int i = 0; i < n; ++i) {
    const std::uint16_t r = spread(response[0][i], response[1][i], response[2][i]);
    sd[i] = o[i] == 2 ? r : sd[i];
  }
  for (std::size_t c = 0; c < 3; ++c) {
    SMX_IVDEP
    for (int i = 0; i < n; ++i) {
      response[c][i] = relativeToColour(response[c][i], inv.scale[c][i], inv.bound[c][i]);
    }
  }
  for (int i = 0; i < n; ++i) {
    const std::uint16_t r = spread(response[0][i], response[1][i], response[2][i]);
    s[i] = o[i] == 2 ? r : s[i];
  }
  for (int j = 0; j < 6; ++j) {
    std::copy_n(samples[j], n, ring.at(y, j, x0));
  }
}

// Strength samples one pixel ahead and behind along the encoding direction over a chunk.
struct ChunkSamples {
  std::int32_t ahead[kChunkPx];
  std::int32_t behind[kChunkPx];
};

void strengthSamples(const TentRows& rows, const ChunkUnits& u, int n, ChunkSamples& out) {
  for (int i = 0; i < n; ++i) {
    const TentPair pair = tentSamples(rows, u, i);
    out.ahead[i] = static_cast<std::int32_t>(pair.ahead);
    out.behind[i] = static_cast<std::int32_t>(pair.behind);
  }
}

// Where the strength at x is at least the minimum and no less than the bilinear sample one pixel
// ahead along the encoding direction and more than the one behind.
struct Candidate {
  int x;
  std::int32_t ahead;
  std::int32_t behind;
};

// The relative values at pixel x of row y, which the strength pass kept in the ring.
Response relativeValuesAt(const SampleRing& ring, int y, int x) {
  Response r{};
  for (int channel = 0; channel < 3; ++channel) {
    r.n[channel] = *ring.relative(y, channel, x);
  }
  return r;
}

// The boundary at a first-order candidate maximum of strength s0: the class from the relative
// values, the position from the derivative strength (`behind`, `centre`, `ahead` at −1, 0,
// +1 px): the relative strength's samples have each their own divisor (whose gradient is
// steepest where the surface colour changes), and dividing by a dark channel's average scales
// its noise up with its signal. Where that parabola has no maximum, the relative strength's.
Boundary firstOrderBoundary(const Response& hereValues, std::int32_t s0, const Candidate& c,
                            std::int32_t behind, std::int32_t centre, std::int32_t ahead) {
  Boundary found = classify(hereValues);
  const auto v = vertexQ8(behind, centre, ahead);
  const std::int32_t offset = v ? *v : vertexQ8(c.behind, s0, c.ahead).value_or(0);
  found.offset = static_cast<std::int16_t>(std::clamp(offset, -128, 128));
  return found;
}

// The boundary at a second-order candidate maximum (x, y), or none when it is a side lobe.
Boundary secondOrderBoundary(const InverseRow& inverse, const StrengthPlanes& strengths,
                             std::int32_t ux, std::int32_t uy, const SampleRing& ring, int y,
                             const Candidate& c) {
  const int x = c.x;
  const ImageView<const std::uint16_t> st = strengths.relative;
  const int w = st.width();
  const int h = st.height();
  const std::uint16_t* here = st.rowPtr(y) + x;
  const std::int32_t s0 = *here;
  // A second-order response has side lobes of about half the peak two pixels out, with the
  // reversed class: such a maximum must also beat the samples two pixels away.
  if (y >= kMargin + 2 && y < h - kMargin - 2 && x >= kMargin + 2 && x < w - kMargin - 2) {
    const std::ptrdiff_t stride = strideOf(st);
    const TapPair far = tapsAlong(ux, uy, 5);
    if (s0 < sampleAt(here, stride, far.ahead) || s0 <= sampleAt(here, stride, far.behind)) {
      return {};
    }
  }
  Response behindSamples{};
  Response aheadSamples{};
  for (int channel = 0; channel < 3; ++channel) {
    const auto k = static_cast<std::size_t>(channel);
    behindSamples.n[k] = *ring.at(y, channel, x);
    aheadSamples.n[k] = *ring.at(y, 3 + channel, x);
  }
  behindSamples = relativeAt(inverse, behindSamples, x);
  aheadSamples = relativeAt(inverse, aheadSamples, x);
  Boundary found = classify(secondOrderResponse(behindSamples, aheadSamples));
  const auto z = zeroCrossingQ8(found, behindSamples, relativeValuesAt(ring, y, x), aheadSamples);
  // Where it does not cross zero there: the vertex through the strength plane's samples.
  const std::int32_t offset = z ? *z : vertexQ8(c.behind, s0, c.ahead).value_or(0);
  found.offset = static_cast<std::int16_t>(std::clamp(offset, -128, 128));
  return found;
}

// The index of the lowest-addressed nonzero byte of a word loaded from memory, and the word
// without it, whatever the byte order.
int firstByte(std::uint64_t word) {
  return std::endian::native == std::endian::little ? std::countr_zero(word) / 8
                                                    : std::countl_zero(word) / 8;
}
std::uint64_t withoutByte(std::uint64_t word, int byte) {
  const int shift = std::endian::native == std::endian::little ? 8 * byte : 56 - 8 * byte;
  return word & ~(std::uint64_t{0xFF} << shift);
}

// Non-maximum suppression of one row chunk [x0, x0 + n): every pixel's test runs branch-free
// (whether a pixel is a maximum is unpredictable; the samples are inside the plane whatever
// the strength), then the costly rest on the maxima only, found eight flags at a time. A
// first-order maximum's derivative samples take the chunk's unit vectors (Q8, the same ±1 px
// along the encoding direction).
void maximaChunk(const InverseRow& inverse, const StrengthPlanes& strengths, const std::uint8_t* o,
                 const std::uint16_t* d, const UnitsQ8& units, const UnitTable& unitTable,
                 const SampleRing& ring, int minStrength, int y, int x0, int n, Boundary* b) {
  const ImageView<const std::uint16_t> st = strengths.relative;
  const std::uint16_t* s = st.rowPtr(y) + x0;
  ChunkUnits unitsQ8;  // NOLINT(cppcoreguidelines-pro-type-member-init): chunkUnits() fills it
  chunkUnits(d + x0, units, n, unitsQ8);
  ChunkSamples samples;  // NOLINT(cppcoreguidelines-pro-type-member-init): filled next
  strengthSamples(tentRows(s, strideOf(st)), unitsQ8, n, samples);
  alignas(8) std::uint8_t isMax[kChunkPx] = {};
  for (int i = 0; i < n; ++i) {
    const std::int32_t s0 = s[i];
    isMax[i] = static_cast<std::uint8_t>(static_cast<int>(s0 >= minStrength) &
                                         static_cast<int>(s0 >= samples.ahead[i]) &
                                         static_cast<int>(s0 > samples.behind[i]));
  }
  const std::uint16_t* derivative = strengths.derivative.rowPtr(y) + x0;
  const std::ptrdiff_t derivativeStride = strideOf(strengths.derivative);
  for (int i8 = 0; i8 < n; i8 += 8) {
    std::uint64_t flags = 0;
    std::memcpy(&flags, isMax + i8, sizeof flags);
    while (flags != 0) {
      const int byte = firstByte(flags);
      flags = withoutByte(flags, byte);
      const int i = i8 + byte;
      const int x = x0 + i;
      const Candidate c{x, samples.ahead[i], samples.behind[i]};
      if (o[x] == 1) {
        const std::uint16_t* pixel = derivative + i;
        const std::int32_t ux = unitsQ8.ux[i];
        const std::int32_t uy = unitsQ8.uy[i];
        b[x] = firstOrderBoundary(relativeValuesAt(ring, y, x), s[i], c,
                                  sampleAt(pixel, derivativeStride, tapQ8(-ux, -uy)), *pixel,
                                  sampleAt(pixel, derivativeStride, tapQ8(ux, uy)));
      } else {  // order 2 (a pixel of order 0 has strength 0: never a maximum)
        b[x] = secondOrderBoundary(inverse, strengths, unitTable.cosOf(d[x]), unitTable.sinOf(d[x]),
                                   ring, y, c);
      }
    }
  }
}

}  // namespace

namespace {

// Row y of the strength planes, with its tile row's divisor (in the ring).
void strengthRow(const Planes3& separated, ImageView<const std::uint8_t> order,
                 ConstDirectionPlane direction, const UnitsQ8& units, const SampleRing& ring,
                 int tileRow, int y, const StrengthPlanes& strengths) {
  const int w = separated[0].width();
  const int h = separated[0].height();
  std::uint16_t* s = strengths.relative.rowPtr(y);
  std::uint16_t* sd = strengths.derivative.rowPtr(y);
  if (y < kMargin || y >= h - kMargin) {
    std::fill_n(s, w, std::uint16_t{0});
    std::fill_n(sd, w, std::uint16_t{0});
    return;
  }
  for (std::uint16_t* row : {s, sd}) {
    std::fill_n(row, kMargin, std::uint16_t{0});
    std::fill_n(row + w - kMargin, kMargin, std::uint16_t{0});
  }
  const std::uint8_t* o = order.rowPtr(y);
  const std::uint16_t* d = direction.rowPtr(y);
  for (int x0 = kMargin; x0 < w - kMargin; x0 += kChunkPx) {
    const int n = std::min(kChunkPx, w - kMargin - x0);
    strengthChunk(separated, o + x0, d + x0, units, ring, ring.inverse(tileRow, x0), y, x0, n,
                  s + x0, sd + x0);
  }
}

// Row y of the boundaries: non-maximum suppression one pixel inside the margin (its samples
// stay in the strength plane's computed area).
void maximaRow(const Planes3& separated, ImageView<const std::uint8_t> order,
               ConstDirectionPlane direction, const UnitsQ8& unitsQ8, const UnitTable& units,
               const SampleRing& ring, const InverseRow& inverse, int minStrength,
               const StrengthPlanes& strengths, int y, BoundaryPlane out) {
  const int w = separated[0].width();
  const int h = separated[0].height();
  Boundary* b = out.rowPtr(y);
  std::fill_n(b, w, Boundary{});
  if (y < kMargin + 1 || y >= h - kMargin - 1) {
    return;
  }
  const std::uint8_t* o = order.rowPtr(y);
  const std::uint16_t* d = direction.rowPtr(y);
  for (int x0 = kMargin + 1; x0 < w - kMargin - 1; x0 += kChunkPx) {
    const int n = std::min(kChunkPx, w - kMargin - 1 - x0);
    maximaChunk(inverse, strengths, o, d, unitsQ8, units, ring, minStrength, y, x0, n, b);
  }
}

// Row y's maxima read the strength up to row y + 3 (the 2×2 of a sample two pixels below).
// Tiles are at least 4 px, so rows y and y + 3 lie in the same or neighbouring tile rows, whose
// divisors the ring holds.
constexpr int kStrengthAhead = 3;
static_assert(static_cast<std::size_t>(kStrengthAhead) < kBoundaryRingSlots);

}  // namespace

void detectBoundaries(const Planes3& separated, ImageView<const std::uint8_t> order,
                      ConstDirectionPlane direction, const UnitTable& units,
                      const TileColours& colours, int minStrength,
                      const RowBlock<std::int16_t>& ringRows, const StrengthPlanes& strengths,
                      BoundaryPlane out) {
  const int h = separated[0].height();
  const UnitsQ8 unitsQ8(units);
  const SampleRing ring(ringRows);
  const auto tileRowOf = [&](int y) { return colours.rows[static_cast<std::size_t>(y)].nearest; };
  int divisorRow = -1;
  // Row by row, the maxima kStrengthAhead rows behind the strength, while the samples they
  // reuse are still in the ring (and the rows in cache).
  for (int y = 0; y < h + kStrengthAhead; ++y) {
    if (y < h) {
      if (tileRowOf(y) != divisorRow) {
        divisorRow = tileRowOf(y);
        inverseColourRow(colours, divisorRow, ring.inverse(divisorRow, 0));
      }
      strengthRow(separated, order, direction, unitsQ8, ring, divisorRow, y, strengths);
    }
    if (y >= kStrengthAhead) {
      const int m = y - kStrengthAhead;
      maximaRow(separated, order, direction, unitsQ8, units, ring, ring.inverse(tileRowOf(m), 0),
                minStrength, strengths, m, out);
    }
  }
}

#if SMX_DEMUX_AVX2
SMX_AVX2_TWIN void avx2::detectBoundaries(const Planes3& separated,
                                          ImageView<const std::uint8_t> order,
                                          ConstDirectionPlane direction, const UnitTable& units,
                                          const TileColours& colours, int minStrength,
                                          const RowBlock<std::int16_t>& ringRows,
                                          const StrengthPlanes& strengths, BoundaryPlane out) {
  demux::detectBoundaries(separated, order, direction, units, colours, minStrength, ringRows,
                          strengths, out);
}
#endif

}  // namespace smx::algo::demux
