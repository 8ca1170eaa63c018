#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "smx/algo/arena.hpp"
#include "smx/algo/boundary_map.hpp"
#include "smx/algo/error.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/range_image.hpp"

// Multi-layer decoding of one projector's stripe boundaries (paper §4.2, ref [31]; DESIGN.md
// item 7; docs/decode.md) into a dense stripe coordinate per camera pixel.
//
// Per frame, integer-only and allocation-free (src/frame/stripe_decode.cpp):
//   1. links: from each boundary pixel, the first boundary of another class met along +axis and
//      along −axis (half-pixel steps from its sub-pixel position, at most maxGapPx);
//   2. votes: the chain of linked boundaries around each pixel, read along +axis, as long as the
//      colours chain (to-colour of one = from-colour of the next), up to 5 each way; every window
//      of 6 transitions holding the pixel decodes to a level (stripe::decodeWindow); the pixel
//      keeps the level most windows agree on and their number;
//   3. curves: boundary pixels of one class that touch (8-neighbourhood) form a boundary curve;
//      the curve's level is the weighted majority (Boyer–Moore, > half the votes, at least
//      minCurveVotes) of its pixels' levels, and it is given to every pixel of the curve, voted
//      or not; a pixel whose own votes (≥ 2) contradict its curve is dropped; then a curve whose
//      links disagree too often (lead to decoded boundaries of other levels than level ± 1, or
//      to a gap unlike the one on the other side) is dropped; each decoded boundary's position
//      becomes the mean over its level's pixels within positionRadiusPx (noise along a curve is
//      independent, the curve locally straight);
//   4. dense coordinate: along rows and columns (each pixel takes the one nearer its own axis),
//      between two consecutive boundaries of the line whose levels are k and k + 1, both decoded,
//      s = k + (distance from the level-k boundary) / (distance between the two), both measured
//      along the pixel's axis: a short interpolation per pixel, no search. Never across a
//      missing, undecoded or non-consecutive boundary, nor a gap over maxGapPx + 1 pixels.
namespace smx::algo {

struct DecodeParams {
  int maxGapPx = 12;          // link search distance along the axis (≈ 2.5 stripe periods)
  int minSeparationQ8 = 192;  // a linked boundary lies at least this far along the axis (Q8 px)
  int minCurveVotes = 8;      // a curve's level needs this many agreeing windows (over its pixels)
  // A decoded curve is dropped when more than this share of its links to decoded boundaries
  // disagree with it (0…100). 33 keeps a curve whose neighbour on one side is wrong along up to
  // two thirds of it; a curve a stripe off has nearly all its links against it.
  int maxNeighbourDisagreePct = 33;
  // A link to level ± 1 disagrees when its gap along the axis exceeds this share of the gap on
  // the other side (0: off, else 101…400). 150 lies between an even spacing (100) and a skipped
  // boundary (200); a curve moved by a fifth of the local period reaches it.
  int maxGapRatioPct = 150;
  int positionRadiusPx = 2;  // boundary positions averaged along their curve (0: off)
  bool curves = true;        // step 3 (off: each pixel is a curve of its own)
};

// Counts of the last run, for evaluation and the debug output.
struct DecodeStats {
  int boundaryPixels = 0;
  int votedPixels = 0;    // with at least one consistent window of their own
  int decodedPixels = 0;  // with a level after step 3
  int curves = 0;         // curves with a majority level
  int densePixels = 0;    // pixels with a stripe coordinate
};

namespace demux {
class UnitTable;
}  // namespace demux
namespace decode {
struct Unit;
}  // namespace decode

class StripeDecoder {
 public:
  [[nodiscard]] static Result<std::size_t> workspaceBytes(int width, int height,
                                                          const DecodeParams& params = {});
  [[nodiscard]] static Result<StripeDecoder> create(int width, int height,
                                                    const DecodeParams& params, Arena& arena);

  // Per frame, one projector: its boundaries and directions (Demultiplexer::boundaries(p),
  // directions(p)) → its stripe coordinate in `stripe` (kNoStripe where none). All planes must be
  // width × height.
  [[nodiscard]] Result<void> run(ConstBoundaryPlane boundaries, ConstDirectionPlane directions,
                                 StripePlane stripe);

  // The boundary level of each pixel after the last run() (1…197, 0 where none): the boundary
  // between stripes level − 1 and level.
  [[nodiscard]] ImageView<const std::int16_t> levels() const {
    return *ImageView<const std::int16_t>::packed(level_, width_, height_);
  }
  [[nodiscard]] const DecodeStats& stats() const { return stats_; }

  // Every step as its plain scalar definition instead of its schedule: the same output bit for
  // bit (PipelineSchedule.* compares them), for the tests and the benchmarks.
  void useReferenceKernels(bool on) { reference_ = on; }

 private:
  StripeDecoder() = default;
  template <class Carver>
  [[nodiscard]] Result<void> carve(Carver& carver);

  template <bool kReference>
  void runSteps(ConstDirectionPlane d, StripePlane stripe);
  void prepare(ConstBoundaryPlane b, ConstDirectionPlane d);
  template <bool kReference, class F>
  void eachBoundary(F f) const;
  template <bool kReference>
  void link(ConstDirectionPlane d);
  template <bool kReference>
  void vote();
  template <bool kReference>
  void joinCurves();
  template <bool kReference>
  void smoothPositions(ConstDirectionPlane d);
  void fill(ConstDirectionPlane d, StripePlane stripe);
  struct PixelXY {
    int x;
    int y;
  };
  static constexpr std::uint8_t kRowAxis = 1;
  static constexpr std::uint8_t kColumnAxis = 2;
  template <class PixelAt>
  void fillLine(ConstDirectionPlane d, StripePlane stripe, std::uint8_t axis, int length,
                PixelAt pixelAt);

  // The default positionRadiusPx, which the schedule's step 3b unrolls.
  static constexpr int kPositionRadius = 2;
  template <int kRadius>
  void sumLevelAround(std::size_t i, decode::Unit u, std::int32_t& sum, std::int32_t& count) const;

  // A boundary's position relative to its pixel centre, Q8 pixels.
  struct Shift {
    std::int16_t x;
    std::int16_t y;
  };

  int width_ = 0;
  int height_ = 0;
  DecodeParams params_;
  DecodeStats stats_;
  bool reference_ = false;
  // Per pixel, row-major without padding (index y · width + x):
  std::span<demux::UnitTable> units_;   // one table
  std::span<std::int32_t> line_;        // the fill's boundary pixels of one row or column
  std::span<std::uint8_t> axis_;        // the fill's kind of line per pixel (kRowAxis, kColumnAxis)
  std::span<std::int32_t> boundaries_;  // boundary pixels' indices, ascending (stats_ counts)
  std::span<std::uint8_t> code_;        // Boundary::transition (0: none)
  std::span<Shift> shift_;              // where the boundary lies
  std::span<std::int32_t> next_;        // linked boundary ahead: its pixel index, or −1
  std::span<std::int32_t> prev_;        // behind
  std::span<std::int16_t> gapNext_;     // distance to the link ahead along the axis, Q8 px
  std::span<std::int16_t> gapPrev_;     // behind
  std::span<std::int32_t> parent_;      // union-find over boundary pixels
  std::span<std::int32_t> weight_;      // per curve root: Boyer–Moore count, then support
  std::span<std::int32_t> total_;       // per curve root: all votes
  std::span<std::int16_t> candidate_;   // per curve root: Boyer–Moore candidate level
  std::span<std::int16_t> votes_;       // windows agreeing on the pixel's own level
  std::span<std::int16_t> own_;         // the pixel's own level (0 = none)
  std::span<std::int16_t> level_;       // final level
};

}  // namespace smx::algo
