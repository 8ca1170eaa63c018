// Direct colour estimation (the baseline of docs/demux.md; paper §2, which argues that the
// colours of superposed patterns cannot be read directly): per-pixel hue classes and the
// boundaries between them along a given direction. This scalar code is the reference; no
// separate schedule exists.
//   Input    Rgb8 image (grey levels), direction plane (BinAngle raw).
//   Colours  int32 Q8 grey levels (value · 256): a pixel exactly, a sample between pixels by
//            bilinear weights in 1/256 pixel, rounded half up. At most 255 · 256 = 65 280.
//   Classes  compared in int32: (max − min) · 1000 and minSaturationPermille · max stay below
//            2^26; confidence 255 · (max − second) / max below 2^24 (truncating division).
//   Steps    u = (cos, sin) Q1.14 from fixed_math, rounded half up to Q8 (≤ 1/512 px off).
//   Offsets  256 · d0 / (d0 − d1) rounded half up, d0 >= 0 >= d1 and d0 − d1 > 0 (the leading
//            channel swaps; ties go to one side only): 256 · d0 < 2^24. Nothing saturates.
#include "smx/algo/direct_colour.hpp"

#include <array>
#include <cstdint>

#include "smx/algo/fixed_math.hpp"

namespace smx::algo {

namespace {

using Channels = std::array<std::int32_t, 3>;  // R, G, B in Q8 grey levels

constexpr std::int32_t kOne = 256;  // one grey level in Q8, and one pixel in Q8
constexpr std::int32_t kHalf = 128;

struct Decision {
  int colour = -1;  // stripe::Colour index, −1: none
  std::int32_t confidence = 0;
};

struct Thresholds {
  std::int32_t minValueQ8;
  std::int32_t minSaturationPermille;
};

Decision decide(const Channels& v, const Thresholds& t) {
  // The brightest channel; of two tied, the later primary in R → G → B → R (half-open hue
  // sectors: yellow is G, cyan B, magenta R).
  std::size_t top = 0;
  for (std::size_t c = 1; c < 3; ++c) {
    top = v[c] > v[top] ? c : top;
  }
  const std::size_t next = (top + 1) % 3;
  top = v[next] == v[top] ? next : top;  // v[0] = v[2] is already R, the first maximum
  const std::int32_t hi = v[top];
  const std::int32_t a = v[(top + 1) % 3];
  const std::int32_t b = v[(top + 2) % 3];
  const std::int32_t second = a > b ? a : b;
  const std::int32_t low = a < b ? a : b;
  if (hi < t.minValueQ8 || hi == low || (hi - low) * 1000 < t.minSaturationPermille * hi) {
    return {};
  }
  // hi > low >= 0 here, so hi > 0.
  return {static_cast<int>(top), (255 * (hi - second)) / hi};
}

Channels pixelQ8(Rgb8 p) {
  return {std::int32_t{p.r} * kOne, std::int32_t{p.g} * kOne, std::int32_t{p.b} * kOne};
}

Channels rawChannels(Rgb8 p) {
  return {std::int32_t{p.r}, std::int32_t{p.g}, std::int32_t{p.b}};
}

// Bilinear sample at (xq, yq) in 1/256 pixel, inside [0, w − 1] × [0, h − 1]. At the last row or
// column the second tap has weight 0 and is clamped onto the first.
Channels sampleQ8(const ConstRgbView& image, std::int32_t xq, std::int32_t yq) {
  const int x0 = xq >> 8;
  const int y0 = yq >> 8;
  const std::int32_t fx = xq & 255;
  const std::int32_t fy = yq & 255;
  const int x1 = x0 + 1 < image.width() ? x0 + 1 : x0;
  const int y1 = y0 + 1 < image.height() ? y0 + 1 : y0;
  const Rgb8* r0 = image.rowPtr(y0);
  const Rgb8* r1 = image.rowPtr(y1);
  const Channels p00 = rawChannels(r0[x0]);
  const Channels p01 = rawChannels(r0[x1]);
  const Channels p10 = rawChannels(r1[x0]);
  const Channels p11 = rawChannels(r1[x1]);
  Channels out{};
  for (std::size_t c = 0; c < 3; ++c) {
    const std::int32_t top = (p00[c] * (kOne - fx)) + (p01[c] * fx);  // grey · 256
    const std::int32_t bottom = (p10[c] * (kOne - fx)) + (p11[c] * fx);
    out[c] = ((top * (kOne - fy)) + (bottom * fy) + kHalf) >> 8;  // grey · 65536 → Q8
  }
  return out;
}

// Q8 offset of the crossing t = d0 / (d0 − d1), d0 >= 0 >= d1 (not both 0): in [0, 256].
std::int32_t crossingQ8(std::int32_t d0, std::int32_t d1) {
  const std::int32_t den = d0 - d1;  // > 0 for classes as decide() makes them; guarded anyway
  return den > 0 ? ((kOne * d0) + (den / 2)) / den : 0;
}

Boundary boundaryOf(int from, int to, std::int32_t offsetQ8, std::int32_t confidence) {
  Boundary b;
  b.offset = static_cast<std::int16_t>(offsetQ8);
  b.transition = Boundary::code(
      stripe::transitionBetween(stripe::colourFromIndex(from), stripe::colourFromIndex(to)));
  b.confidence =
      static_cast<std::uint8_t>(confidence < 0 ? 0 : (confidence > 255 ? 255 : confidence));
  return b;
}

std::int32_t smaller(std::int32_t a, std::int32_t b) {
  return a < b ? a : b;
}

// The boundary pixel (x, y) records, if any (see the header).
Boundary boundaryAt(const ConstRgbView& image, int x, int y, std::uint16_t direction,
                    const Thresholds& t) {
  const Channels here = pixelQ8(image.rowPtr(y)[x]);
  const Decision a = decide(here, t);
  if (a.colour < 0) {
    return {};
  }
  const BinAngle angle{direction};
  const std::int32_t dx = (std::int32_t{algo::cos(angle)} + 32) >> 6;  // Q1.14 → Q8
  const std::int32_t dy = (std::int32_t{algo::sin(angle)} + 32) >> 6;
  const std::int32_t xq = x * kOne;
  const std::int32_t yq = y * kOne;
  const auto ia = static_cast<std::size_t>(a.colour);

  Boundary best;
  std::int32_t bestDistance = kOne;

  const Channels ahead = sampleQ8(image, xq + dx, yq + dy);
  const Decision b = decide(ahead, t);
  if (b.colour >= 0 && b.colour != a.colour) {
    const auto ib = static_cast<std::size_t>(b.colour);
    const std::int32_t offset = crossingQ8(here[ia] - here[ib], ahead[ia] - ahead[ib]);
    if (offset <= kHalf) {
      best = boundaryOf(a.colour, b.colour, offset, smaller(a.confidence, b.confidence));
      bestDistance = offset;
    }
  }

  const Channels behind = sampleQ8(image, xq - dx, yq - dy);
  const Decision c = decide(behind, t);
  if (c.colour >= 0 && c.colour != a.colour) {
    const auto ic = static_cast<std::size_t>(c.colour);
    const std::int32_t offset =
        crossingQ8(behind[ic] - behind[ia], here[ic] - here[ia]) - kOne;  // in [−256, 0]
    if (offset > -kHalf && -offset < bestDistance) {
      best = boundaryOf(c.colour, a.colour, offset, smaller(a.confidence, c.confidence));
    }
  }
  return best;
}

}  // namespace

ColourClass classifyColour(Rgb8 pixel, const DirectColourParams& params) {
  const Decision d = decide(pixelQ8(pixel), {params.minValue * kOne, params.minSaturationPermille});
  if (d.colour < 0) {
    return {};
  }
  return {true, stripe::colourFromIndex(d.colour), static_cast<std::uint8_t>(d.confidence)};
}

Result<void> directColourBoundaries(ConstRgbView image, ConstDirectionPlane direction,
                                    BoundaryPlane out, const DirectColourParams& params) {
  if (direction.width() != image.width() || direction.height() != image.height() ||
      out.width() != image.width() || out.height() != image.height()) {
    return fail(Errc::kSizeMismatch, "direct colour: direction and output must match the image");
  }
  if (params.minValue < 0 || params.minValue > 255 || params.minSaturationPermille < 0 ||
      params.minSaturationPermille > 1000) {
    return fail(Errc::kInvalidArgument,
                "direct colour: minValue 0 to 255, minSaturationPermille 0 to 1000");
  }
  const Thresholds t{params.minValue * kOne, params.minSaturationPermille};
  const int w = image.width();
  const int h = image.height();
  for (int y = 0; y < h; ++y) {
    Boundary* o = out.rowPtr(y);
    const std::uint16_t* d = direction.rowPtr(y);
    for (int x = 0; x < w; ++x) {
      // p ± u stays inside the image one pixel in from the border.
      o[x] = (x < 1 || y < 1 || x >= w - 1 || y >= h - 1) ? Boundary{}
                                                          : boundaryAt(image, x, y, d[x], t);
    }
  }
  return {};
}

}  // namespace smx::algo
