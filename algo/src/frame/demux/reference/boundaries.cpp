// Reference of stages 4–5 (demux_reference.hpp): per pixel the relative values, the response
// and its strengths, then per pixel the maximum test along the encoding direction and the
// boundary's class and position. Schedule: schedule/boundaries.cpp (chunks of rows, bilinear
// samples as tents over runs of equal offsets, the relative product as int16 high and low
// halves, maxima three rows behind the strength in a ring).
#include <algorithm>
#include <cstdint>
#include <optional>

#include "demux_reference.hpp"

namespace smx::algo::demux::reference {

namespace {

constexpr int kMargin = 3;  // strengths stay 3 px inside the image; maxima 4 px
constexpr int kScaleShift = 4;
constexpr int kProductShift = kInverseShift - kRelativeShift - kScaleShift;  // 9

// The divisor of one tile and channel: 2^24 / average scaled into int16, and the largest |D|
// whose relative value still fits int16.
struct Divisor {
  std::int32_t scale;
  std::int32_t bound;
};

// Q8 offsets along the encoding direction: the unit vector Q1.14 >> 6 is one pixel.
struct OffsetQ8 {
  std::int32_t x;
  std::int32_t y;
};

struct Values {
  std::int32_t c[3];
};

// The 2×2 neighbourhood of (x, y) + q and its fractions.
struct Corner {
  int x;
  int y;
  std::int32_t fx;
  std::int32_t fy;
};

Corner cornerOf(int x, int y, OffsetQ8 q) {
  return {x + (q.x >> 8), y + (q.y >> 8), q.x & 255, q.y & 255};
}

// The bilinear sample, rounded half up.
template <class T>
std::int32_t bilinear(ImageView<const T> plane, int x, int y, OffsetQ8 q) {
  const Corner k = cornerOf(x, y, q);
  const auto at = [&](int i, int j) { return std::int64_t{plane(k.x + i, k.y + j)}; };
  const std::int64_t top = at(0, 0) * (256 - k.fx) + at(1, 0) * k.fx;
  const std::int64_t bottom = at(0, 1) * (256 - k.fx) + at(1, 1) * k.fx;
  return static_cast<std::int32_t>((top * (256 - k.fy) + bottom * k.fy + 32768) >> 16);
}

// a + (b − a)·f / 256 rounded down to an even number: 2 · ((b − a)·f >> 9). The schedule's
// blend of separated values (an int16 high-half product); so are the samples here.
std::int32_t blendEven(std::int32_t a, std::int32_t b, std::int32_t f) {
  return a + 2 * (((b - a) * f) >> 9);
}

std::int32_t sampleD(ImageView<const std::int16_t> plane, int x, int y, OffsetQ8 q) {
  const Corner k = cornerOf(x, y, q);
  const auto at = [&](int i, int j) { return std::int32_t{plane(k.x + i, k.y + j)}; };
  return blendEven(blendEven(at(0, 0), at(1, 0), k.fx), blendEven(at(0, 1), at(1, 1), k.fx), k.fy);
}

std::int32_t spread(const Values& v) {
  return std::max({v.c[0], v.c[1], v.c[2]}) - std::min({v.c[0], v.c[1], v.c[2]});
}

// The transition from the falling (first smallest) to the rising (first largest) channel; the
// confidence from how far the third channel is from their midpoint.
Boundary classify(const Values& n) {
  int to = 0;
  int from = 0;
  for (int c = 1; c < 3; ++c) {
    to = n.c[c] > n.c[to] ? c : to;
    from = n.c[c] < n.c[from] ? c : from;
  }
  Boundary b;
  b.transition = to == from ? std::uint8_t{0}
                            : Boundary::code(stripe::transitionBetween(
                                  stripe::colourFromIndex(from), stripe::colourFromIndex(to)));
  const std::int32_t high = n.c[to];
  const std::int32_t low = n.c[from];
  const std::int32_t range = high - low;
  std::int32_t conf = 0;
  if (range > 0) {
    const std::int32_t third = n.c[0] + n.c[1] + n.c[2] - high - low;
    const std::int32_t dev = std::abs(2 * third - high - low);
    conf = 255 * (range - dev) / range;
  }
  b.confidence = static_cast<std::uint8_t>(std::clamp(conf, 0, 255));
  return b;
}

// The vertex of the parabola through (−1, behind), (0, centre), (1, ahead) in Q8, where centre
// is a strict maximum of it.
std::optional<std::int32_t> vertexQ8(std::int32_t behind, std::int32_t centre, std::int32_t ahead) {
  const std::int32_t den = ahead + behind - 2 * centre;
  if (den >= 0) {
    return std::nullopt;
  }
  return 128 * (behind - ahead) / den;
}

// Where (to − from) of the response's samples at −1, 0, +1 px crosses zero from + to −, Q8.
std::optional<std::int32_t> zeroCrossingQ8(const Boundary& b, const Values& behind,
                                           const Values& here, const Values& ahead) {
  const auto to = static_cast<std::size_t>(stripe::indexOf(stripe::to(b.kind())));
  const auto from = static_cast<std::size_t>(stripe::indexOf(stripe::from(b.kind())));
  const std::int32_t before = behind.c[to] - behind.c[from];
  const std::int32_t at = here.c[to] - here.c[from];
  const std::int32_t after = ahead.c[to] - ahead.c[from];
  if (at >= 0 && after < 0) {
    return 256 * at / (at - after);
  }
  if (before > 0 && at < 0) {
    return -256 + 256 * before / (before - at);
  }
  return std::nullopt;
}

std::int16_t clampOffset(std::int32_t offset) {
  return static_cast<std::int16_t>(std::clamp(offset, -128, 128));
}

}  // namespace

void boundaries(const Planes3& separated, ImageView<const std::uint8_t> order,
                ConstDirectionPlane direction, const UnitTable& units,
                std::span<const std::uint32_t> inverse, const DemuxLayout& layout, int minStrength,
                const StrengthPlanes& strengths, BoundaryPlane out) {
  const int w = layout.width;
  const int h = layout.height;
  const int t = layout.params.tilePx;
  // The pixel's divisor: its nearest tile's.
  const auto divisor = [&](int x, int y, int c) {
    const std::size_t tile =
        static_cast<std::size_t>(y / t) * static_cast<std::size_t>(layout.tilesX()) +
        static_cast<std::size_t>(x / t);
    const auto scale =
        static_cast<std::int32_t>((inverse[tile * 3 + static_cast<std::size_t>(c)] + 8) >> 4);
    const std::int32_t largest = (32767 << kProductShift) / scale;
    return Divisor{scale, std::min(largest, 32767)};
  };
  // D relative to the colour at (x, y), Q4.11: (clamp(D) · scale) >> 9.
  const auto relative = [&](const Values& d, int x, int y) {
    Values r{};
    for (int c = 0; c < 3; ++c) {
      const Divisor k = divisor(x, y, c);
      r.c[c] = (std::clamp(d.c[c], -k.bound, k.bound) * k.scale) >> kProductShift;
    }
    return r;
  };
  const auto dAt = [&](int x, int y) {
    return Values{{separated[0](x, y), separated[1](x, y), separated[2](x, y)}};
  };
  const auto samplesAt = [&](int x, int y, OffsetQ8 q) {
    Values v{};
    for (std::size_t c = 0; c < 3; ++c) {
      v.c[c] = sampleD(separated[c], x, y, q);
    }
    return v;
  };
  const auto unitQ8 = [&](int x, int y) {
    const std::uint16_t angle = direction(x, y);
    return OffsetQ8{units.cosOf(angle) >> 6, units.sinOf(angle) >> 6};
  };
  const auto difference = [](const Values& a, const Values& b) {
    return Values{{a.c[0] - b.c[0], a.c[1] - b.c[1], a.c[2] - b.c[2]}};
  };

  // Strengths: of the response relative to the colour, and of the response itself.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::int32_t s = 0;
      std::int32_t sd = 0;
      const bool inside = x >= kMargin && y >= kMargin && x < w - kMargin && y < h - kMargin;
      if (inside && order(x, y) == 1) {
        s = spread(relative(dAt(x, y), x, y));
        sd = spread(dAt(x, y));
      } else if (inside && order(x, y) == 2) {
        const OffsetQ8 u = unitQ8(x, y);
        const Values n = difference(samplesAt(x, y, {-u.x, -u.y}), samplesAt(x, y, u));
        s = spread(relative(n, x, y));
        sd = spread(n);
      }
      strengths.relative(x, y) = static_cast<std::uint16_t>(s);
      strengths.derivative(x, y) = static_cast<std::uint16_t>(sd);
    }
  }

  // Maxima along the encoding direction, one pixel inside the strengths.
  const ImageView<const std::uint16_t> st = strengths.relative;
  const ImageView<const std::uint16_t> sd = strengths.derivative;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      out(x, y) = Boundary{};
      if (x < kMargin + 1 || y < kMargin + 1 || x >= w - kMargin - 1 || y >= h - kMargin - 1) {
        continue;
      }
      const std::int32_t s0 = st(x, y);
      const OffsetQ8 u = unitQ8(x, y);
      const OffsetQ8 back{-u.x, -u.y};
      const std::int32_t ahead = bilinear(st, x, y, u);
      const std::int32_t behind = bilinear(st, x, y, back);
      if (s0 < minStrength || s0 < ahead || s0 <= behind) {
        continue;
      }
      const auto strengthVertex = [&] { return vertexQ8(behind, s0, ahead).value_or(0); };
      if (order(x, y) == 1) {
        Boundary b = classify(relative(dAt(x, y), x, y));
        const auto v = vertexQ8(bilinear(sd, x, y, back), sd(x, y), bilinear(sd, x, y, u));
        b.offset = clampOffset(v ? *v : strengthVertex());
        out(x, y) = b;
        continue;
      }
      // Second order (order 0 has strength 0: never a maximum). Its side lobes, two pixels out
      // with the reversed class, must not beat the samples there.
      const std::uint16_t angle = direction(x, y);
      const OffsetQ8 far{units.cosOf(angle) >> 5, units.sinOf(angle) >> 5};
      if (x >= kMargin + 2 && y >= kMargin + 2 && x < w - kMargin - 2 && y < h - kMargin - 2 &&
          (s0 < bilinear(st, x, y, far) || s0 <= bilinear(st, x, y, {-far.x, -far.y}))) {
        continue;
      }
      const Values behindValues = relative(samplesAt(x, y, back), x, y);
      const Values aheadValues = relative(samplesAt(x, y, u), x, y);
      Boundary b = classify(difference(behindValues, aheadValues));
      const auto z = zeroCrossingQ8(b, behindValues, relative(dAt(x, y), x, y), aheadValues);
      b.offset = clampOffset(z ? *z : strengthVertex());
      out(x, y) = b;
    }
  }
}

}  // namespace smx::algo::demux::reference
