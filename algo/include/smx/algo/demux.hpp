#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "smx/algo/arena.hpp"
#include "smx/algo/boundary_map.hpp"
#include "smx/algo/error.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/jobs.hpp"

// Orientation demultiplexing (paper §3, §4.2–4.3; docs/demux.md): from one camera image in which
// the same colour-stripe pattern of 1–3 projectors is superposed at different orientations,
// each projector's stripe boundaries with their colour transitions.
//
// Stages, all per frame, integer-only and allocation-free (src/frame/demux/schedule/*.cpp, each
// with its plain scalar definition in src/frame/demux/reference/*.cpp):
//   1. binomial smoothing of each channel (×16 fixed point);
//   2. per tile, the magnitude-weighted histogram of doubled gradient angles over a window of
//      tiles; its lobes, refined by a local weighted mean, are matched to each projector's
//      predicted encoding direction (sign and identity come from the rig); a median over
//      neighbouring tiles removes strays;
//   3. per pixel, the directional derivative that cancels the other patterns present: along
//      the projector's own axis (alone), perpendicular to the other axis (two patterns), or the
//      mixed second derivative perpendicular to both others (three patterns);
//   4. division by the locally averaged colour;
//   5. non-maximum suppression along the encoding axis, sub-pixel position (parabola, or the
//      second derivative's zero crossing), the transition class (from the falling and the
//      rising channel) and a confidence.
namespace smx::algo {

inline constexpr int kMaxProjectors = 3;

// Tunables, with the defaults the accuracy tests were measured with.
struct DemuxParams {
  int tilePx = 8;                // direction / colour-average tile size
  int windowTiles = 3;           // histogram window: windowTiles × windowTiles tiles (odd)
  int histogramStride = 2;       // gradients sampled every n-th pixel in x and y for the histogram
  int minGradientGrey = 4;       // gradient magnitude (grey levels per pixel) counted in histograms
  int lobeToleranceDeg = 30;     // a lobe is a projector's if within this of its predicted axis
                                 // (and within half the angle to the nearest other axis)
  int minLobeSharePct = 8;       // and holds at least this share of the window's weight
  int minStrengthPermille = 80;  // boundary strength, relative to the local average colour
  int minContrastGrey = 4;       // and in grey levels per pixel (max − min over the channels)
  int smoothPasses = 1;          // step 1: 3×3 binomial passes (σ 0.7 px; two: σ 1 px)
  bool normaliseColour = true;   // step 4
};

// Which build of the vectorised stages run() calls: a choice of schedule, not of algorithm, as
// every build gives the same output bit for bit (DemuxReference.* compares each with the scalar
// reference of src/frame/demux/reference).
enum class DemuxSchedule : std::uint8_t {
  kAutomatic,  // x86-64: the AVX2 build where the CPU has it; else the baseline
  kBaseline,   // the baseline build (SSE2 on x86-64, NEON on aarch64)
};

// The frame geometry fixed at init: image size, projector count and each projector's predicted
// encoding direction per tile (BinAngle raw, +axis towards growing stripe index), from
// calibration at a nominal depth (predictEncodingAngles in encoding_prediction.hpp).
struct DemuxLayout {
  int width = 0;
  int height = 0;
  int projectors = 0;
  DemuxParams params;

  [[nodiscard]] int tilesX() const { return (width + params.tilePx - 1) / params.tilePx; }
  [[nodiscard]] int tilesY() const { return (height + params.tilePx - 1) / params.tilePx; }
  [[nodiscard]] std::size_t tileCount() const {
    return static_cast<std::size_t>(tilesX()) * static_cast<std::size_t>(tilesY());
  }
};

// What the direction stage found in one tile for one projector.
struct TileDirection {
  std::uint16_t angle = 0;   // BinAngle raw of the encoding direction (estimated or predicted)
  std::uint8_t present = 0;  // 1 when the pattern's lobe was found in the tile's window
};

namespace demux {
class UnitTable;
struct TileInterp;
struct Kernels;
}  // namespace demux

class Demultiplexer {
 public:
  // The most arena bytes create() takes for this layout, alignment padding included. `lanes`
  // (1 to one per projector): how many projectors' boundaries run() may detect at once, each
  // lane with its own working rows and strength planes.
  [[nodiscard]] static Result<std::size_t> workspaceBytes(const DemuxLayout& layout, int lanes = 1);

  // predictedAngles: tileCount() × projectors values, tile-major (tile t, projector p at
  // t * projectors + p); copied into the arena.
  [[nodiscard]] static Result<Demultiplexer> create(
      const DemuxLayout& layout, std::span<const std::uint16_t> predictedAngles, Arena& arena,
      DemuxSchedule schedule = DemuxSchedule::kAutomatic, int lanes = 1);

  // Per frame: every projector's boundaries and directions. The image must be width × height.
  // Given a JobRunner, the tile histograms and the matching of their lobes run in bands of
  // tile rows and the projectors' boundaries are detected on the lanes at once; the planes are
  // the same either way.
  [[nodiscard]] Result<void> run(ConstRgbView image, JobRunner& jobs);
  [[nodiscard]] Result<void> run(ConstRgbView image);

  [[nodiscard]] const DemuxLayout& layout() const { return layout_; }
  [[nodiscard]] ConstBoundaryPlane boundaries(int projector) const;
  [[nodiscard]] ConstDirectionPlane directions(int projector) const;
  // tileCount() entries for the projector, row-major over tiles.
  [[nodiscard]] std::span<const TileDirection> tileDirections(int projector) const;

  // Evaluation seam (stripemux eval's "true directions" baseline): from now on run() takes the
  // tile directions from here instead of estimating them. projectors × tileCount entries,
  // projector-major as tileDirections() reads them; copied, no allocation.
  [[nodiscard]] Result<void> fixTileDirections(std::span<const TileDirection> tiles);

  // Debug view of the last run(): the projector's separated derivative per channel, before the
  // division by the local colour (32 × grey level per pixel for the first order). With one lane
  // the last projector's planes share the smoothed image's memory, so they hold until the next
  // run().
  [[nodiscard]] ImageView<const std::int16_t> separated(int projector, int channel) const;

 private:
  Demultiplexer() = default;
  template <class Carver>
  [[nodiscard]] Result<void> carve(Carver& carver);

  // A lane's working memory: for a band of tile rows' histograms, a band of rows' separation
  // and detecting one projector's boundaries besides its planes. Lane 0's rows are filterRows_
  // and workRows_.
  struct LaneScratch {
    std::span<std::int32_t> filterRows;
    std::span<std::int16_t> workRows;
    ImageView<std::uint16_t> strength;
    ImageView<std::uint16_t> derivativeStrength;
  };

  DemuxLayout layout_;
  int lanes_ = 1;
  const demux::Kernels* kernels_ = nullptr;  // the build of the vectorised stages run() calls
  std::span<std::uint16_t> predicted_;
  std::span<demux::UnitTable> units_;  // one table
  std::span<demux::TileInterp> columns_;
  std::span<demux::TileInterp> rows_;
  std::span<std::int16_t> rowScratch_;
  std::span<std::int32_t> filterRows_;          // separate()'s ring of filtered rows
  std::span<std::int16_t> workRows_;            // separate()'s rows of derivatives, units, tiles
  std::span<std::uint32_t> tileHistograms_;     // tileCount × 64 bins
  std::span<std::int32_t> tileMoments_;         // tileCount × 64 first moments per bin
  std::span<std::uint32_t> tileColourSums_;     // tileCount × 3
  std::span<std::uint32_t> tileInverseColour_;  // tileCount × 3: 2^24 / average
  std::span<std::uint16_t> tileScratch_;        // tileCount: the direction median filter's
  std::span<TileDirection> tileDirections_;     // projectors × tileCount
  bool fixedDirections_ = false;                // fixTileDirections() was called
  std::array<ImageView<std::int16_t>, 3> smoothed_;
  // Per projector; with one lane the last projector's planes share smoothed_'s memory
  // (separate() reads each smoothed row before it writes there).
  std::array<std::array<ImageView<std::int16_t>, 3>, kMaxProjectors> separated_;
  std::array<ImageView<std::uint8_t>, kMaxProjectors> order_;
  std::array<LaneScratch, kMaxProjectors> laneScratch_;
  std::array<BoundaryPlane, kMaxProjectors> boundaries_;
  std::array<DirectionPlane, kMaxProjectors> directions_;
};

}  // namespace smx::algo
