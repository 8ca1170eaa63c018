// Triangulation and trust in one pass over the image (depth_trust.hpp): the schedule of
// Triangulator::run() followed by trustDepth(), which stay the reference. Each row goes in chunks
// of kChunk pixels, in two loops:
//   - every pixel's |∇s| from its four neighbours, without a branch, in uint32 lanes (the
//     vectoriser's: NEON, SSE2);
//   - per pixel with a coordinate and a resolvable gradient, the two triangulations and the
//     confidence, with the tables' pointers in registers (Triangulator::Lookup).
// A pixel that fails the gradient is never triangulated. The output is the reference's bit for
// bit (TriangulationWithTrust.OnePassGivesTheReferenceOnRandomStripes).
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

#include "smx/algo/depth_trust.hpp"
#include "trust/trust_shared.hpp"

namespace smx::algo {

namespace {

constexpr int kChunk = 64;

// No derivative on an axis. Every real |∇s| is below it: the axes' magnitudes are below 2^31
// (differences of values ≥ 0), and max(a, 7/8·a + 1/2·b) ≤ 11/8 · a < 2^32 − 1.
constexpr std::uint32_t kNoGradient = std::numeric_limits<std::uint32_t>::max();

std::uint32_t distance(std::int32_t p, std::int32_t q) {
  const auto up = static_cast<std::uint32_t>(p);
  const auto uq = static_cast<std::uint32_t>(q);
  return p > q ? up - uq : uq - up;
}

// The reference's axisDerivative: |trunc((b − a) / 2)| = ⌊|b − a| / 2⌋ with both neighbours,
// one-sided with one, kNoGradient with none. c ≥ 0 where the result is used.
std::uint32_t derivative(std::int32_t a, std::int32_t c, std::int32_t b) {
  const std::uint32_t central = distance(a, b) >> 1U;
  const std::uint32_t after = distance(b, c);
  const std::uint32_t before = distance(c, a);
  const std::uint32_t withA = b >= 0 ? central : before;
  const std::uint32_t withoutA = b >= 0 ? after : kNoGradient;
  return a >= 0 ? withA : withoutA;
}

// |∇s| (the reference's blend of the two axes) of pixels 0 … n − 1 of a chunk; `row` holds
// the values of pixels −1 … n.
void gradients(const StripeQ16* row, const StripeQ16* up, const StripeQ16* down, int n,
               std::uint32_t* out) {
  for (int k = 0; k < n; ++k) {
    const std::int32_t c = row[k + 1];
    const std::uint32_t dx = derivative(row[k], c, row[k + 2]);
    const std::uint32_t dy = derivative(up[k], c, down[k]);
    const std::uint32_t hi = std::max(dx, dy);
    const std::uint32_t lo = std::min(dx, dy);
    const std::uint32_t blend = hi - (hi >> 3U) + (lo >> 1U);
    const std::uint32_t gradient = std::max(blend, hi);
    out[k] = (dx == kNoGradient || dy == kNoGradient) ? kNoGradient : gradient;
  }
}

struct Limits {
  std::uint32_t maxGradient = 0;  // the largest |∇s| whose stripes are resolvable
  DepthTrustParams params;
};

Limits limitsOf(const DepthTrustParams& p) {
  // g · m > 2^24 ⇔ g > ⌊2^24 / m⌋ for integers g ≥ 0, m > 0.
  constexpr std::uint32_t kOneOverPxQ24 = 1U << 24U;
  return {p.minStripeWidthQ8 > 0 ? kOneOverPxQ24 / static_cast<std::uint32_t>(p.minStripeWidthQ8)
                                 : kNoGradient - 1,
          p};
}

struct Trusted {
  std::uint16_t z = kNoDepth;
  std::uint8_t confidence = 0;
};

// Pixel i with coordinate s ≥ 0 and a resolvable gradient: the reference's steps after the
// gradient.
template <bool kPerPixel>
Trusted trusted(const Triangulator::Lookup& t, std::size_t i, std::int32_t s,
                std::uint32_t gradient, const Limits& l) {
  constexpr Trusted kNone{kNoDepth, 0};
  const std::uint16_t z = t.depth<kPerPixel>(i, s);
  if (z == kNoDepth) {
    return kNone;
  }
  const std::int64_t ahead = s + ((std::int64_t{gradient} * l.params.boundaryErrorQ8 + 128) >> 8);
  if (ahead >= Triangulator::kMaxStripe) {
    return kNone;
  }
  const std::uint16_t zAhead = t.depth<kPerPixel>(i, static_cast<StripeQ16>(ahead));
  if (zAhead == kNoDepth) {
    return kNone;
  }
  const std::int64_t spread = std::int64_t{2} * (zAhead > z ? zAhead - z : z - zAhead);
  const std::uint8_t c = confidenceOf(spread, z, l.params);
  return c == 0 ? kNone : Trusted{z, c};
}

constexpr std::array<StripeQ16, kChunk + 2> kNoRow = [] {
  std::array<StripeQ16, kChunk + 2> row{};
  row.fill(kNoStripe);
  return row;
}();

template <bool kPerPixel>
void trustRows(const Triangulator::Lookup t, ConstStripePlane stripe, DepthPlane depth,
               ImageView<std::uint8_t> confidence, const Limits l) {
  const int w = stripe.width();
  const int h = stripe.height();
  std::array<StripeQ16, kChunk + 2> edge{};
  std::array<std::uint32_t, kChunk> gradient{};
  for (int y = 0; y < h; ++y) {
    const StripeQ16* at = stripe.rowPtr(y);
    const StripeQ16* up = y > 0 ? stripe.rowPtr(y - 1) : nullptr;
    const StripeQ16* down = y + 1 < h ? stripe.rowPtr(y + 1) : nullptr;
    std::uint16_t* z = depth.rowPtr(y);
    std::uint8_t* c = confidence.rowPtr(y);
    const std::size_t base = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    for (int x0 = 0; x0 < w; x0 += kChunk) {
      const int n = std::min(kChunk, w - x0);
      // Pixels x0 − 1 … x0 + n of this row, kNoStripe outside the image.
      const StripeQ16* around = at + x0 - 1;
      if (x0 == 0 || x0 + n == w) {
        for (std::size_t k = 0; k < static_cast<std::size_t>(n) + 2; ++k) {
          const int x = x0 - 1 + static_cast<int>(k);
          edge[k] = x >= 0 && x < w ? at[x] : kNoStripe;
        }
        around = edge.data();
      }
      gradients(around, up != nullptr ? up + x0 : kNoRow.data(),
                down != nullptr ? down + x0 : kNoRow.data(), n, gradient.data());
      for (int k = 0; k < n; ++k) {
        const std::int32_t s = around[k + 1];
        const std::uint32_t g = gradient[static_cast<std::size_t>(k)];
        Trusted out{kNoDepth, 0};
        if (s >= 0 && g <= l.maxGradient) {
          out = trusted<kPerPixel>(t, base + static_cast<std::size_t>(x0 + k), s, g, l);
        }
        z[x0 + k] = out.z;
        c[x0 + k] = out.confidence;
      }
    }
  }
}

}  // namespace

Result<void> triangulateTrusted(const Triangulator& triangulator, ConstStripePlane stripe,
                                DepthPlane depth, ImageView<std::uint8_t> confidence,
                                const DepthTrustParams& params) {
  if (auto ok = checkTrustArguments(triangulator, stripe, depth, confidence, params); !ok) {
    return ok;
  }
  const Triangulator::Lookup lookup = triangulator.lookup();
  if (triangulator.perPixelNumerators()) {
    trustRows<true>(lookup, stripe, depth, confidence, limitsOf(params));
  } else {
    trustRows<false>(lookup, stripe, depth, confidence, limitsOf(params));
  }
  return {};
}

}  // namespace smx::algo
