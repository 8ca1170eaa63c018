#pragma once

// The per-frame stages of orientation demultiplexing (demux.hpp) as run() calls them: their
// schedules, one file each in schedule/, each with its plain scalar definition in reference/
// (demux_reference.hpp). Integer only, no allocation: every buffer is passed in, carved from the
// arena at create().

#include <array>
#include <cstdint>
#include <span>

#include "smx/algo/boundary_map.hpp"
#include "smx/algo/demux.hpp"
#include "smx/algo/image_view.hpp"

// GCC's hint that a loop carries no dependence through memory: the per-pixel loops over many
// int16 rows have more pointers than its run-time alias checks take. Other compilers (the
// lint's clang) do without.
#if defined(__GNUC__) && !defined(__clang__)
#define SMX_IVDEP _Pragma("GCC ivdep")
#else
#define SMX_IVDEP
#endif

// x86-64 with GCC: the vectorised stages also have an AVX2 build. Each twin (SMX_AVX2_TWIN) is
// compiled for AVX2 with the stage's whole body inlined into it (flatten), so the helpers it
// calls are AVX2 code too, while every out-of-line function stays baseline code (no AVX2 leaks
// into what the baseline path calls). run() takes the twins where the CPU has AVX2, as OpenCV's
// dispatch does for the Sobel the speed is measured against. Integer arithmetic: both builds
// give the same output (DemuxKernels.* compares them).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SMX_DEMUX_AVX2 1
#define SMX_AVX2_TWIN [[gnu::target("avx2"), gnu::flatten]]
#else
#define SMX_DEMUX_AVX2 0
#endif

namespace smx::algo::demux {

inline constexpr int kBins = 64;               // doubled-angle histogram bins (2π)
inline constexpr int kBinRaw = 65536 / kBins;  // BinAngle raw units per bin
inline constexpr int kUnitShift = 14;          // unit vectors are Q1.14
inline constexpr int kUnit = 1 << kUnitShift;
inline constexpr int kRelativeShift = 11;  // separated values: Q4.11 of the local average
inline constexpr int kInverseShift = 24;   // tile inverse colour: 2^24 / average
inline constexpr int kSmoothScale = 16;    // smoothed planes hold 16 × grey level
inline constexpr int kColourFloor = 8 * kSmoothScale;  // averages below 8 grey levels clamp

// A unit vector (Q1.14) from a BinAngle by a 1024-entry table (nearest entry: <= 0.18°).
class UnitTable {
 public:
  static constexpr int kEntries = 1024;
  void fill();
  // The entry nearest an angle: cosOf(angle) is entry e's cosine, sinOf(angle) entry e − 256's.
  [[nodiscard]] static std::size_t entryOf(std::uint16_t angle) {
    return static_cast<std::size_t>(((angle + 32U) >> 6U) & (kEntries - 1U));
  }
  [[nodiscard]] std::int32_t cosOf(std::uint16_t angle) const { return cos_[entryOf(angle)]; }
  [[nodiscard]] std::int32_t sinOf(std::uint16_t angle) const {
    return cosOf(static_cast<std::uint16_t>(angle - 16384U));
  }

 private:
  std::array<std::int16_t, kEntries> cos_{};
};

// Matched 5-tap prefilter / first / second derivative (Farid & Simoncelli's, in integers, the
// second derivative adjusted so that Σ j²·d2 / 2 · Σ p = (Σ j·d1)², i.e. d2⊗p, p⊗d2 and d1⊗d1
// measure ∂xx, ∂yy and ∂xy on one scale: 66 560 and 66 564 per unit): directional derivatives
// steered from them cancel a pattern at any angle, where 3-point differences leak several
// per cent of it.
inline constexpr std::array<std::int32_t, 5> kPre = {8, 64, 112, 64, 8};
inline constexpr std::array<std::int32_t, 5> kD1 = {-27, -75, 0, 75, 27};
inline constexpr std::array<std::int32_t, 5> kD2 = {65, 0, -130, 0, 65};
inline constexpr int kDerivShift = 15;  // filter scale / 2: D values are 2 × the S derivative

using Planes3 = std::array<ImageView<std::int16_t>, 3>;

// Stage 1: S_c = 16 × I_c smoothed by `passes` 3×3 binomial passes (edges repeated; 0 passes:
// unsmoothed). rowScratch holds kSmoothRowScratch × width values.
inline constexpr std::size_t kSmoothRowScratch = 3;
void smoothChannels(ConstRgbView image, const Planes3& out, int passes,
                    std::span<std::int16_t> rowScratch);

// Per tile and channel, Σ S over the tile's pixels.
void sumTileColours(const Planes3& smoothed, int tilePx, std::span<std::uint32_t> sums);

// 2^24 / max(window average, floor) per tile and channel, the window being windowTiles² tiles.
void inverseTileColours(std::span<const std::uint32_t> sums, const DemuxLayout& layout,
                        bool normalise, std::span<std::uint32_t> inverse);

// Rows of values of one width, carved from the arena: the working rows of histogramTiles() and
// separate().
template <class T>
class RowBlock {
 public:
  RowBlock() = default;
  RowBlock(std::span<T> memory, int width)
      : memory_(memory), width_(static_cast<std::size_t>(width)) {}
  [[nodiscard]] static std::size_t valuesFor(std::size_t rows, int width) {
    return rows * static_cast<std::size_t>(width);
  }
  [[nodiscard]] T* row(std::size_t index) const { return memory_.data() + index * width_; }

 private:
  std::span<T> memory_;
  std::size_t width_ = 0;
};

// Stage 2a: each tile's histogram of its samples' doubled gradient angles (weights per bin and
// first moments Σ w·(angle − bin centre) per bin).
struct SampleGrid {
  int stride = 2;
  int width = 0;   // samples per row
  int height = 0;  // sample rows
};
[[nodiscard]] SampleGrid sampleGrid(const DemuxLayout& layout);
// rows: kHistogramRows working rows of the image's width (run() lends separate()'s).
inline constexpr std::size_t kHistogramRows = 4;
// Only the tiles of tile rows [firstTileRow, endTileRow) (clipped) are written: bands of tile
// rows are independent, each with its own working rows.
void histogramTiles(const Planes3& smoothed, const DemuxLayout& layout,
                    const RowBlock<std::int32_t>& rows, std::span<std::uint32_t> tileHistograms,
                    std::span<std::int32_t> tileMoments, int firstTileRow, int endTileRow);

// Stage 2b: lobes of each tile's window histogram matched to the predicted directions, then a
// 3×3 median of the found tiles' offsets from the prediction; tiles without the lobe take their
// neighbours'. out[p * tileCount + t]; scratch holds tileCount values. In two parts: the
// matching, tile by tile (bands of tile rows [firstTileRow, endTileRow) are independent), then
// what needs every tile's match.
void matchTileLobes(const DemuxLayout& layout, std::span<const std::uint32_t> tileHistograms,
                    std::span<const std::int32_t> tileMoments,
                    std::span<const std::uint16_t> predicted, std::span<TileDirection> out,
                    int firstTileRow, int endTileRow);
void finishDirections(const DemuxLayout& layout, std::span<const std::uint32_t> tileHistograms,
                      std::span<const std::int32_t> tileMoments,
                      std::span<const std::uint16_t> predicted, std::span<TileDirection> out,
                      std::span<std::uint16_t> scratch);

// Bilinear interpolation between tile centres (tile i's centre is pixel i·T + (T−1)/2), per
// column or row: the lower tile, the upper one, the upper one's weight in 1/256 and the
// nearest tile.
struct TileInterp {
  std::int16_t lower;
  std::int16_t upper;
  std::int16_t weight;
  std::int16_t nearest;
};
void tileInterpolation(int pixels, int tilePx, int tiles, std::span<TileInterp> out);

// separate()'s rows: a ring of horizontally filtered rows (int32; 5 rows × 3 channels × 3
// filters) and the current row's derivatives, unit vectors and tile data (int16).
inline constexpr std::size_t kFilterRows = 45;
inline constexpr std::size_t kWorkRows = 33;

// The signed difference a − b of two BinAngle raw values, wrapped into [−2^15, 2^15).
[[nodiscard]] inline std::int32_t wrapDiff(std::uint16_t a, std::uint16_t b) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(a - b));
}

// Rows [begin, end) of a plane that a stage writes: any split of the image into such bands gives
// the same planes, so lanes may each take one.
struct RowRange {
  int begin = 0;
  int end = 0;
};

// Every projector's direction plane, rows `rows`: its tile angles interpolated bilinearly between
// tile centres (as wrapped differences from the lower-left tile's). band: kInterpolationRows
// working rows of the image's width (run() lends separate()'s filter rows), the per-pixel terms
// shared by a band of rows between two tile rows' centres.
inline constexpr std::size_t kInterpolationRows = 4;
void interpolateDirections(const DemuxLayout& layout, std::span<const TileDirection> tiles,
                           std::span<const TileInterp> columns, std::span<const TileInterp> rows,
                           const RowBlock<std::int32_t>& band, std::span<const DirectionPlane> out,
                           RowRange outRows);

// Stage 3 for every projector in one sweep: per projector, the separated derivative per channel
// (D, 32 × grey level per pixel for the first order) and the derivative order per pixel (1 or
// 2; 0 on the border), for the output rows `band`; it reads the input's rows band.begin − 2 …
// band.end + 1.
// Output row y is written after row y + 2 of smoothed is read, and no row of smoothed is read
// twice, so with one band over the whole image one projector's separated planes may take
// smoothed's memory; bands run at once may not (each reads the rows beside it).
void separate(const Planes3& smoothed, const DemuxLayout& layout,
              std::span<const TileDirection> tiles, std::span<const TileInterp> columns,
              std::span<const TileInterp> rows, const UnitTable& units,
              const RowBlock<std::int32_t>& filtered, const RowBlock<std::int16_t>& work,
              std::span<const DirectionPlane> directions, std::span<const Planes3> separated,
              std::span<const ImageView<std::uint8_t>> order, RowRange band);

// detectBoundaries()'s minStrength: the parameter's per mille of the local colour in Q4.11.
[[nodiscard]] constexpr int minStrengthQ11(const DemuxParams& params) {
  return (params.minStrengthPermille << kRelativeShift) / 1000;
}

// Stages 4–5 for one projector: the response relative to the local colour, its strength
// max − min over the channels, then non-maximum suppression along the encoding direction,
// sub-pixel offset and class. ringRows: a ring of kBoundaryRingRows working rows of the image's
// width (run() lends separate()'s) keeping the relative values and second-order samples of the
// last kBoundaryRingSlots strength rows for their maxima, and the divisor of two tile rows.
inline constexpr std::size_t kBoundaryRingSlots = 4;
inline constexpr std::size_t kBoundaryRingRows = kBoundaryRingSlots * 9 + std::size_t{2} * 6;
// The int16 working rows run() carves: separate()'s, then detectBoundaries()' ring.
inline constexpr std::size_t kSharedWorkRows =
    kWorkRows > kBoundaryRingRows ? kWorkRows : kBoundaryRingRows;
// The divisor: per tile and channel 2^24 / average (inverseTileColours), each pixel taking its
// nearest tile's (the columns' and rows' `nearest`).
struct TileColours {
  std::span<const std::uint32_t> inverse;
  int tilesX;
  std::span<const TileInterp> columns;
  std::span<const TileInterp> rows;
};
// The strength planes (max − min over the channels), shared by the projectors: of the response
// relative to the local colour, which finds the boundaries, and of the derivative itself, which
// places them.
struct StrengthPlanes {
  ImageView<std::uint16_t> relative;
  ImageView<std::uint16_t> derivative;
};
void detectBoundaries(const Planes3& separated, ImageView<const std::uint8_t> order,
                      ConstDirectionPlane direction, const UnitTable& units,
                      const TileColours& colours, int minStrength,
                      const RowBlock<std::int16_t>& ringRows, const StrengthPlanes& strengths,
                      BoundaryPlane out);

// The stages that have twins, as run() calls them.
struct Kernels {
  decltype(&smoothChannels) smooth;
  decltype(&histogramTiles) histogram;
  decltype(&matchTileLobes) lobes;
  decltype(&finishDirections) finish;  // of the directions, after every band's lobes
  decltype(&interpolateDirections) interpolation;
  decltype(&separate) separation;
  decltype(&detectBoundaries) boundaries;
};
// The baseline build (SSE2 on x86-64, NEON on aarch64).
[[nodiscard]] const Kernels& baselineKernels();
// The AVX2 twins where they are built and the CPU runs them; else the baseline.
[[nodiscard]] const Kernels& fastestKernels();

#if SMX_DEMUX_AVX2
namespace avx2 {
using SmoothChannels = decltype(smoothChannels);
using HistogramTiles = decltype(histogramTiles);
using MatchTileLobes = decltype(matchTileLobes);
using FinishDirections = decltype(finishDirections);
using InterpolateDirections = decltype(interpolateDirections);
using Separate = decltype(separate);
using DetectBoundaries = decltype(detectBoundaries);
SmoothChannels smoothChannels;
HistogramTiles histogramTiles;
MatchTileLobes matchTileLobes;
FinishDirections finishDirections;
InterpolateDirections interpolateDirections;
Separate separate;
DetectBoundaries detectBoundaries;
}  // namespace avx2
#endif

}  // namespace smx::algo::demux
