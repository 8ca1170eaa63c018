#pragma once

#include <cstdint>

#include "smx/algo/boundary_map.hpp"
#include "smx/algo/error.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/stripe_code.hpp"

// The baseline the paper's §2 argues against: "direct colour estimation", the front end of a
// single-projector colour-stripe decoder (hue thresholding, refs [11, 31]) applied as is to the
// superposed image. Each pixel is classified R, G or B by hue; a boundary is where the class
// changes along a projector's encoding direction. Where one pattern lights the surface this
// works; where two are superposed the colours are sums of two primaries (yellow, cyan, magenta,
// or a doubled primary) and the class no longer says which stripe of which projector is there.
// docs/demux.md ("Baseline: direct colour estimation") has the rule and the measured comparison
// with orientation demultiplexing. Per frame: integer arithmetic only, no heap, no exceptions.
namespace smx::algo {

// Tunables of the hue classifier.
struct DirectColourParams {
  int minValue = 24;                // grey levels: a pixel whose brightest channel is below this
                                    // is too dark to classify
  int minSaturationPermille = 200;  // HSV saturation (max − min) / max below this: unsaturated
};

// The hue class of one colour. present is false for "none": too dark, or unsaturated.
struct ColourClass {
  bool present = false;
  stripe::Colour colour = stripe::Colour::kRed;
  // 255 · (max − second) / max: the dominant channel's lead relative to its value (the
  // saturation with respect to the class's primary; 255 for a pure primary, 0 at a tie).
  std::uint8_t confidence = 0;
};

// The hue classifier (hue thresholding). With max ≥ second ≥ min the channel values:
//   none       when max < minValue, or (max − min) · 1000 < minSaturationPermille · max (HSV
//              saturation), or max == min (no hue);
//   otherwise  the colour of the brightest channel, i.e. the primary whose hue sector holds the
//              hue. The sectors are 120° wide, centred on the primaries and half-open: a hue
//              exactly between two primaries (two channels tie) goes to the later one in
//              R → G → B → R, so yellow is G, cyan B, magenta R, with confidence 0.
[[nodiscard]] ColourClass classifyColour(Rgb8 pixel, const DirectColourParams& params = {});

// The stripe boundaries the hue classes imply along a projector's encoding direction, in the
// demultiplexer's output format (boundary_map.hpp), for every pixel of `out`:
//   u = the unit vector of direction(p); the colour ahead is the image bilinearly sampled at
//   p + u (exactly one pixel ahead), the colour behind at p − u, each classified as above.
//   With a = class(p), a boundary lies between p and p + u when the class ahead b is present
//   and differs from a (a present). Its position is where the linear interpolation of the
//   channels a and b between the two samples crosses (a leads at p, b ahead): t = d0 / (d0 − d1)
//   with d = I_a − I_b, t in (0, 1) pixel. Likewise behind, with t − 1 in (−1, 0). Pixel p
//   records the crossing within half a pixel of its centre (ahead: t ≤ ½, behind: t − 1 > −½;
//   the nearer if both), so each boundary is recorded once per line along the direction:
//   offset = 256 · t (Q8, |offset| ≤ 128), transition = (colour before → colour after) read
//   along +u, confidence = the smaller of the two sides' classifier confidences. Otherwise the
//   pixel holds no boundary; so do the pixels of the one-pixel image border.
// Numerics: samples are Q8 grey levels (bilinear weights in 1/256 pixel; u from the Q1.14 sin /
// cos of fixed_math.hpp rounded to Q8), sums and products in int32 (at most 255 · 65536).
// Errors: kSizeMismatch when direction or out is not the image's size; kInvalidArgument when a
// parameter is out of range (minValue 0–255, minSaturationPermille 0–1000).
[[nodiscard]] Result<void> directColourBoundaries(ConstRgbView image, ConstDirectionPlane direction,
                                                  BoundaryPlane out,
                                                  const DirectColourParams& params = {});

}  // namespace smx::algo
