// Stage 2b, the schedule of matchTileLobes() and finishDirections() (reference:
// reference/directions.cpp): local stripe-encoding directions (paper §3.2) from the tile histograms
// of histogram.cpp.
//   Per tile window (windowTiles² tiles, sums in 64 bits): lobes are maxima of π/2-wide angle
//   windows stepped by π/4 that are not at a window edge; each is refined by two mean-shift
//   steps on the histogram (exact weighted mean of the samples in the bins within ±2 of the
//   centre) and matched to the nearest predicted axis (within the tolerance and half the angle to
//   the nearest other axis, holding the minimum share), or to another lobe within the tolerance
//   that the tile's own histogram holds three times more of; the doubled angle is halved and its
//   sign taken from the prediction. Found tiles then grow into absent ones (the lobe nearest
//   their found neighbours' direction), a 3×3 median (twice) of the offsets from the prediction
//   follows, and tiles still without the lobe take their neighbours' offset.
#include <cstdint>

#include "demux_kernels.hpp"

namespace smx::algo::demux {

namespace {

constexpr int kRefineBins = 2;  // mean over ±2 bins: ±14° doubled, ±7° of orientation
constexpr int kBinShift = 10;   // kBinRaw = 2^10
constexpr int kMaxLobes = 8;
constexpr int kShareBins = 3;  // a lobe's mass: ±3 bins (±17° doubled, ±8.4° of orientation)

struct Lobe {
  std::uint16_t angle2 = 0;    // refined doubled angle
  bool used = false;           // matched, or holding too small a share to match
  std::uint32_t tileMass = 0;  // the centre tile's own histogram within ±kShareBins
};

// A window that straddles two surfaces (an occlusion edge, a sharp bend) holds a lobe of each for
// the same projector; the one nearest the prediction is often the other surface's (the flat
// background's, say). A lobe the centre tile itself holds kTileMassFactor times more of is the
// tile's own surface: decisive enough that the tile's few samples do not flip it by noise.
constexpr std::uint64_t kTileMassFactor = 3;

// |a − b| of two BinAngle raw values, wrapped: in [0, 2^15].
std::int32_t wrapDistance(std::uint16_t a, std::uint16_t b) {
  const std::int32_t d = wrapDiff(a, b);
  return d < 0 ? -d : d;
}

// The direction of the axis of doubled angle angle2 that lies within a quarter turn of
// `reference` (the doubled angle has lost the sign; the prediction or the neighbours give it).
std::uint16_t axisTowards(std::uint16_t angle2, std::uint16_t reference) {
  auto angle = static_cast<std::uint16_t>(angle2 >> 1U);
  const std::int32_t off = wrapDiff(angle, reference);
  if (off > 16384 || off < -16384) {
    angle = static_cast<std::uint16_t>(angle + 32768U);
  }
  return angle;
}

// Two mean-shift steps on the window histogram: the weighted mean doubled angle of the samples in
// the bins within ±kRefineBins of the current centre, exact from each bin's weight and first
// moment (Σ w·(angle − bin centre)).
Lobe refine(int peakBin, const std::uint32_t (&weights)[kBins],
            const std::int64_t (&moments)[kBins]) {
  Lobe lobe;
  std::int32_t centre = peakBin * kBinRaw;  // unwrapped doubled angle
  for (int iteration = 0; iteration < 2; ++iteration) {
    const std::int32_t centreBin = (centre + kBinRaw / 2) >> kBinShift;  // floor division
    std::int64_t moment = 0;
    std::uint64_t mass = 0;
    for (int k = centreBin - kRefineBins; k <= centreBin + kRefineBins; ++k) {
      const auto bin = static_cast<std::size_t>(k & (kBins - 1));
      mass += weights[bin];
      moment += static_cast<std::int64_t>(weights[bin]) * (k * kBinRaw - centre) + moments[bin];
    }
    if (mass == 0) {
      break;
    }
    centre += static_cast<std::int32_t>(moment / static_cast<std::int64_t>(mass));
  }
  lobe.angle2 = static_cast<std::uint16_t>(static_cast<std::uint32_t>(centre) & 0xFFFFU);
  return lobe;
}

// The lobe a projector takes: `nearest` (the free lobe nearest its predicted doubled axis pred2),
// unless another free lobe within its tolerance holds kTileMassFactor times more of the centre
// tile's own weight.
int preferTileLobe(const Lobe (&lobes)[kMaxLobes], int lobeCount, int nearest, std::uint16_t pred2,
                   std::int32_t tolerance) {
  int best = nearest;
  for (int l = 0; l < lobeCount; ++l) {
    if (lobes[l].used || l == nearest) {
      continue;
    }
    if (wrapDistance(lobes[l].angle2, pred2) <= tolerance &&
        std::uint64_t{lobes[l].tileMass} > kTileMassFactor * std::uint64_t{lobes[best].tileMass}) {
      best = l;
    }
  }
  return best;
}

// Sums of tile histograms over a set of tiles: first moments in 64 bits; weights in 32 (a tile's
// bin holds at most 81 samples × 3 channels of weight < 2^14, a window at most 81 tiles).
struct BinSums {
  std::uint32_t weights[kBins] = {};
  std::int64_t moments[kBins] = {};

  void clear() {
    for (int k = 0; k < kBins; ++k) {
      weights[k] = 0;
      moments[k] = 0;
    }
  }
  void add(const BinSums& other) {
    for (int k = 0; k < kBins; ++k) {
      weights[k] += other.weights[k];
      moments[k] += other.moments[k];
    }
  }
  void subtract(const BinSums& other) {
    for (int k = 0; k < kBins; ++k) {
      weights[k] -= other.weights[k];
      moments[k] -= other.moments[k];
    }
  }
};

// The window histogram's lobes: interior maxima of the 8 angle windows (π/2 wide, stepped by
// π/4), each the first maximum of its two halves' first maxima, refined; `own` is the centre
// tile's histogram. Returns how many.
int findLobes(const BinSums& window, const std::uint32_t* own, std::uint64_t minSharePct,
              Lobe (&lobes)[kMaxLobes]) {
  const auto& hist = window.weights;
  const auto& moment = window.moments;
  std::uint64_t total = 0;
  for (const std::uint64_t weight : hist) {
    total += weight;
  }
  int lobeCount = 0;
  int peakBins[kMaxLobes];
  if (total == 0) {
    return 0;
  }
  constexpr int kHalf = kBins / 8;
  int halfBest[8];
  for (int b = 0; b < 8; ++b) {
    int best = b * kHalf;
    for (int k = best + 1; k < (b + 1) * kHalf; ++k) {
      best = hist[k] > hist[best] ? k : best;
    }
    halfBest[b] = best;
  }
  for (int aw = 0; aw < 8; ++aw) {
    const int start = aw * kHalf;
    const int upper = halfBest[(aw + 1) % 8];
    const int best =
        hist[upper] > hist[halfBest[aw]] ? start + kHalf + upper % kHalf : halfBest[aw];
    if (best == start || best == start + kBins / 4 - 1 || hist[best % kBins] == 0) {
      continue;
    }
    const int bin = best % kBins;
    bool seen = false;
    for (int l = 0; l < lobeCount; ++l) {
      seen = seen || peakBins[l] == bin;
    }
    if (seen) {
      continue;
    }
    peakBins[lobeCount] = bin;
    lobes[lobeCount] = refine(bin, hist, moment);
    // The lobe's mass: the window histogram within ±kShareBins of the refined peak.
    const int centre = ((lobes[lobeCount].angle2 + kBinRaw / 2) / kBinRaw) % kBins;
    std::uint64_t mass = 0;
    for (int k = centre - kShareBins; k <= centre + kShareBins; ++k) {
      mass += hist[(k + kBins) % kBins];
    }
    // A lobe below the minimum share of the window's weight never matches.
    lobes[lobeCount].used = mass * 100 < minSharePct * total;
    for (int k = centre - kShareBins; k <= centre + kShareBins; ++k) {
      lobes[lobeCount].tileMass += own[(k + kBins) % kBins];
    }
    ++lobeCount;
  }
  return lobeCount;
}

constexpr int kMaxWindowTiles = 9;  // DemuxParams::windowTiles, as create() validates it

// The window histogram of every tile along a tile row, as separable sums sliding along x: each
// tile column's sum over the window's tile rows is formed once, and the window moves by adding
// the column that enters and subtracting the one that leaves, instead of adding windowTiles²
// tiles per tile. Integer sums are exact, so the result equals the direct sum bit for bit.
class WindowSums {
 public:
  WindowSums(std::span<const std::uint32_t> histograms, std::span<const std::int32_t> moments,
             int tilesX, int tilesY, int radius)
      : histograms_(histograms),
        moments_(moments),
        tilesX_(tilesX),
        tilesY_(tilesY),
        radius_(radius) {}

  // The window of tile (tx, ty), summed afresh; step(tx + 1) may follow.
  void moveTo(int tx, int ty) {
    ty_ = ty;
    window_.clear();
    for (int i = tx - radius_ > 0 ? tx - radius_ : 0; i <= tx + radius_ && i < tilesX_; ++i) {
      BinSums& column = slot(i);
      sumColumn(i, column);
      window_.add(column);
    }
  }
  // From the window of tile (tx − 1, ty) to that of (tx, ty).
  void step(int tx) {
    const int leaving = tx - radius_ - 1;
    const int entering = tx + radius_;
    if (leaving >= 0) {
      window_.subtract(slot(leaving));
    }
    if (entering < tilesX_) {
      BinSums& column = slot(entering);  // the leaving column's slot
      sumColumn(entering, column);
      window_.add(column);
    }
  }
  [[nodiscard]] const BinSums& sums() const { return window_; }

 private:
  BinSums& slot(int tileX) { return columns_[static_cast<std::size_t>(tileX % (2 * radius_ + 1))]; }
  // Tile column i's histograms over the tile rows ty − r … ty + r inside the grid.
  void sumColumn(int i, BinSums& column) const {
    const int j0 = ty_ - radius_ > 0 ? ty_ - radius_ : 0;
    const int j1 = ty_ + radius_ < tilesY_ ? ty_ + radius_ : tilesY_ - 1;
    const std::uint32_t* weights = histograms_.data() + offset(i, j0);
    const std::int32_t* moments = moments_.data() + offset(i, j0);
    for (int k = 0; k < kBins; ++k) {
      column.weights[k] = weights[k];
      column.moments[k] = moments[k];
    }
    for (int j = j0 + 1; j <= j1; ++j) {
      weights = histograms_.data() + offset(i, j);
      moments = moments_.data() + offset(i, j);
      for (int k = 0; k < kBins; ++k) {
        column.weights[k] += weights[k];
        column.moments[k] += moments[k];
      }
    }
  }
  [[nodiscard]] std::size_t offset(int i, int j) const {
    return (static_cast<std::size_t>(j) * static_cast<std::size_t>(tilesX_) +
            static_cast<std::size_t>(i)) *
           kBins;
  }

  std::span<const std::uint32_t> histograms_;
  std::span<const std::int32_t> moments_;
  int tilesX_;
  int tilesY_;
  int radius_;
  int ty_ = 0;
  BinSums window_;
  BinSums columns_[kMaxWindowTiles];
};

// Where a projector's lobe was not found (its pattern faint or absent), the direction of the
// tiles around that found it is a better guess than the flat-surface prediction: the mean offset
// from the prediction over the present tiles within ±kFillRadius tiles, as wrapped differences.
// Presence stays 0.
constexpr int kFillRadius = 2;

// One projector's tile directions beside the predictions they are offsets from.
struct ProjectorTiles {
  std::span<TileDirection> tiles;
  std::span<const std::uint16_t> predicted;  // tile-major, every projector
  std::size_t projector;
  std::size_t projectors;
  int tilesX;
  int tilesY;

  [[nodiscard]] std::uint16_t prediction(std::size_t tile) const {
    return predicted[tile * projectors + projector];
  }
  // Calls visit(tile index) for each tile within ±radius of (tx, ty).
  template <class Visit>
  void forEachAround(int tx, int ty, int radius, Visit visit) const {
    const int i0 = tx - radius > 0 ? tx - radius : 0;
    const int i1 = tx + radius < tilesX ? tx + radius : tilesX - 1;
    const int j0 = ty - radius > 0 ? ty - radius : 0;
    const int j1 = ty + radius < tilesY ? ty + radius : tilesY - 1;
    for (int j = j0; j <= j1; ++j) {
      const std::size_t row = static_cast<std::size_t>(j) * static_cast<std::size_t>(tilesX);
      for (int i = i0; i <= i1; ++i) {
        visit(row + static_cast<std::size_t>(i));
      }
    }
  }
  // Calls visit(offset from the prediction) for each found tile within ±radius of (tx, ty).
  template <class Visit>
  void forEachFoundAround(int tx, int ty, int radius, Visit visit) const {
    forEachAround(tx, ty, radius, [&](std::size_t n) {
      if (tiles[n].present == 1) {
        visit(wrapDiff(tiles[n].angle, prediction(n)));
      }
    });
  }
};

ProjectorTiles projectorTiles(const DemuxLayout& layout, std::span<const std::uint16_t> predicted,
                              std::span<TileDirection> out, std::size_t projector) {
  const std::size_t tileCount = layout.tileCount();
  return {out.subspan(projector * tileCount, tileCount), predicted,       projector,
          static_cast<std::size_t>(layout.projectors),   layout.tilesX(), layout.tilesY()};
}

// Calls fix(tile index, tx, ty) for every tile.
template <class Fix>
void forEachTile(const ProjectorTiles& tiles, Fix fix) {
  for (int ty = 0; ty < tiles.tilesY; ++ty) {
    for (int tx = 0; tx < tiles.tilesX; ++tx) {
      fix(static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles.tilesX) +
              static_cast<std::size_t>(tx),
          tx, ty);
    }
  }
}

// Calls fix(tiles, tile index, tx, ty) for every tile of every projector whose lobe is absent.
template <class Fix>
void forEachAbsentTile(const DemuxLayout& layout, std::span<const std::uint16_t> predicted,
                       std::span<TileDirection> out, Fix fix) {
  for (std::size_t p = 0; p < static_cast<std::size_t>(layout.projectors); ++p) {
    const ProjectorTiles tiles = projectorTiles(layout, predicted, out, p);
    forEachTile(tiles, [&](std::size_t t, int tx, int ty) {
      if (tiles.tiles[t].present == 0) {
        fix(tiles, t, tx, ty);
      }
    });
  }
}

// Where a projector's lobe lies beyond the tolerance of the flat-surface prediction (a surface
// turned far from the nominal one, as towards a sphere's rim), the found neighbours' direction is
// the better centre: the found tiles grow into absent ones, one ring per pass, each absent tile
// taking its window lobe nearest the mean offset of its found 3×3 neighbours, if within
// kGrowTolerance2 and not nearer another projector's direction in the tile. A ring is marked
// kGrowing during its pass, so that it grows from found tiles only, and kGrown during the next,
// which retries only the absent tiles next to it (the others' neighbourhoods did not change).
constexpr int kGrowPasses = 6;
constexpr std::int32_t kGrowTolerance2 = 2 * 20 * 65536 / 360;  // 20° of orientation, doubled
constexpr std::uint8_t kGrowing = 2;
constexpr std::uint8_t kGrown = 3;

void growFoundTiles(const DemuxLayout& layout, std::span<const std::uint32_t> tileHistograms,
                    std::span<const std::int32_t> tileMoments,
                    std::span<const std::uint16_t> predicted, std::span<TileDirection> out) {
  const auto minSharePct = static_cast<std::uint64_t>(layout.params.minLobeSharePct);
  const auto projectors = static_cast<std::size_t>(layout.projectors);
  const std::size_t tileCount = layout.tileCount();
  WindowSums windows(tileHistograms, tileMoments, layout.tilesX(), layout.tilesY(),
                     layout.params.windowTiles / 2);
  for (int pass = 0; pass < kGrowPasses; ++pass) {
    bool grew = false;
    forEachAbsentTile(
        layout, predicted, out, [&](const ProjectorTiles& tiles, std::size_t t, int tx, int ty) {
          std::int32_t sum = 0;
          std::int32_t count = 0;
          bool nextToNew = pass == 0;
          tiles.forEachAround(tx, ty, 1, [&](std::size_t n) {
            const std::uint8_t present = tiles.tiles[n].present;
            if (present == 1 || present == kGrown) {
              sum += wrapDiff(tiles.tiles[n].angle, tiles.prediction(n));
              ++count;
              nextToNew = nextToNew || present == kGrown;
            }
          });
          if (count == 0 || !nextToNew) {
            return;
          }
          const auto guess = static_cast<std::uint16_t>(tiles.prediction(t) +
                                                        static_cast<std::uint16_t>(sum / count));
          windows.moveTo(tx, ty);
          Lobe lobes[kMaxLobes];
          const int lobeCount =
              findLobes(windows.sums(), tileHistograms.data() + t * kBins, minSharePct, lobes);
          const auto guess2 = static_cast<std::uint16_t>(guess << 1U);
          int best = -1;
          std::int32_t bestDiff = kGrowTolerance2 + 1;
          for (int l = 0; l < lobeCount; ++l) {
            const std::int32_t diff = wrapDistance(lobes[l].angle2, guess2);
            bool nearerOther = false;
            for (std::size_t q = 0; q < projectors; ++q) {
              const TileDirection& other = out[q * tileCount + t];
              if (q == tiles.projector || other.present == 0) {
                continue;
              }
              nearerOther = nearerOther ||
                            wrapDistance(lobes[l].angle2,
                                         static_cast<std::uint16_t>(other.angle << 1U)) <= diff;
            }
            if (!lobes[l].used && !nearerOther && diff < bestDiff) {
              bestDiff = diff;
              best = l;
            }
          }
          if (best < 0) {
            return;
          }
          tiles.tiles[t].angle = axisTowards(lobes[best].angle2, guess);
          tiles.tiles[t].present = kGrowing;
          grew = true;
        });
    for (TileDirection& d : out) {
      d.present = d.present == kGrown ? 1 : (d.present == kGrowing ? kGrown : d.present);
    }
    if (!grew) {
      break;
    }
  }
  for (TileDirection& d : out) {
    d.present = d.present == kGrown ? 1 : d.present;
  }
}

void sort2(std::int32_t& a, std::int32_t& b) {
  const std::int32_t low = a < b ? a : b;
  b = a < b ? b : a;
  a = low;
}

// The median of 9 values: a 19-exchange selection network (Paeth's; checked on every 0/1 input),
// branch-free where sorting mispredicts.
std::int32_t median9(std::int32_t (&p)[9]) {
  sort2(p[1], p[2]), sort2(p[4], p[5]), sort2(p[7], p[8]);
  sort2(p[0], p[1]), sort2(p[3], p[4]), sort2(p[6], p[7]);
  sort2(p[1], p[2]), sort2(p[4], p[5]), sort2(p[7], p[8]);
  sort2(p[0], p[3]), sort2(p[5], p[8]), sort2(p[4], p[7]);
  sort2(p[3], p[6]), sort2(p[1], p[4]), sort2(p[2], p[5]);
  sort2(p[4], p[7]), sort2(p[4], p[2]), sort2(p[6], p[4]);
  sort2(p[4], p[2]);
  return p[4];
}

// Tile estimates scatter by a few degrees where lobes are broad (three patterns) and single tiles
// go astray; the field itself varies slowly. Each found tile takes the median offset from the
// prediction over the found tiles of its 3×3 neighbourhood (the upper median of an even count;
// through scratch, so that every median sees unfiltered neighbours). The neighbourhood's missing
// tiles count as below or above everything, as many below as keep the median of 9 on the found
// tiles' median.
void medianFilterTiles(const DemuxLayout& layout, std::span<const std::uint16_t> predicted,
                       std::span<TileDirection> out, std::span<std::uint16_t> scratch) {
  constexpr std::int32_t kBelowAll = -65536;
  constexpr std::int32_t kAboveAll = 65536;
  for (std::size_t p = 0; p < static_cast<std::size_t>(layout.projectors); ++p) {
    const ProjectorTiles tiles = projectorTiles(layout, predicted, out, p);
    forEachTile(tiles, [&](std::size_t t, int tx, int ty) {
      scratch[t] = tiles.tiles[t].angle;
      if (tiles.tiles[t].present == 0) {
        return;
      }
      std::int32_t values[9];
      int count = 0;
      tiles.forEachFoundAround(tx, ty, 1, [&](std::int32_t value) { values[count++] = value; });
      for (int k = count, below = (9 - count) / 2; k < 9; ++k, --below) {
        values[k] = below > 0 ? kBelowAll : kAboveAll;
      }
      scratch[t] = static_cast<std::uint16_t>(tiles.prediction(t) +
                                              static_cast<std::uint16_t>(median9(values)));
    });
    for (std::size_t t = 0; t < tiles.tiles.size(); ++t) {
      tiles.tiles[t].angle = scratch[t];
    }
  }
}

void fillAbsentTiles(const DemuxLayout& layout, std::span<const std::uint16_t> predicted,
                     std::span<TileDirection> out) {
  forEachAbsentTile(layout, predicted, out,
                    [](const ProjectorTiles& tiles, std::size_t t, int tx, int ty) {
                      std::int32_t sum = 0;
                      std::int32_t count = 0;
                      tiles.forEachFoundAround(tx, ty, kFillRadius, [&](std::int32_t value) {
                        sum += value;
                        ++count;
                      });
                      if (count > 0) {
                        tiles.tiles[t].angle = static_cast<std::uint16_t>(
                            tiles.prediction(t) + static_cast<std::uint16_t>(sum / count));
                      }
                    });
}

}  // namespace

void matchTileLobes(const DemuxLayout& layout, std::span<const std::uint32_t> tileHistograms,
                    std::span<const std::int32_t> tileMoments,
                    std::span<const std::uint16_t> predicted, std::span<TileDirection> out,
                    int firstTileRow, int endTileRow) {
  const int tilesX = layout.tilesX();
  const int tilesY = layout.tilesY();
  const int ty0 = firstTileRow < 0 ? 0 : firstTileRow;
  const int ty1 = endTileRow > tilesY ? tilesY : endTileRow;
  const int r = layout.params.windowTiles / 2;
  const int projectors = layout.projectors;
  const std::size_t tileCount = layout.tileCount();
  const int tolerance2 = (layout.params.lobeToleranceDeg * 2 * 65536) / 360;
  const auto minSharePct = static_cast<std::uint64_t>(layout.params.minLobeSharePct);
  WindowSums windows(tileHistograms, tileMoments, tilesX, tilesY, r);

  for (int ty = ty0; ty < ty1; ++ty) {
    for (int tx = 0; tx < tilesX; ++tx) {
      const std::size_t tile = static_cast<std::size_t>(ty) * static_cast<std::size_t>(tilesX) +
                               static_cast<std::size_t>(tx);
      if (tx == 0) {
        windows.moveTo(0, ty);
      } else {
        windows.step(tx);
      }
      Lobe lobes[kMaxLobes];
      const int lobeCount =
          findLobes(windows.sums(), tileHistograms.data() + tile * kBins, minSharePct, lobes);

      // Greedy matching: repeatedly the closest (projector, lobe) pair within tolerance.
      bool assigned[kMaxProjectors] = {false, false, false};
      for (int p = 0; p < projectors; ++p) {
        TileDirection& d = out[static_cast<std::size_t>(p) * tileCount + tile];
        d.angle =
            predicted[tile * static_cast<std::size_t>(projectors) + static_cast<std::size_t>(p)];
        d.present = 0;
      }
      // Projector p's predicted axis in the tile, as a doubled angle.
      const auto predicted2 = [&](int p) {
        return static_cast<std::uint16_t>(
            predicted[tile * static_cast<std::size_t>(projectors) + static_cast<std::size_t>(p)]
            << 1U);
      };
      // Each projector's tolerance: the cap, and at most half the doubled-angle distance to the
      // nearest other predicted axis (tilted surfaces turn stripes far from the prediction; two
      // patterns 90° apart allow 45°, three 60° apart 30°).
      std::int32_t tolerance[kMaxProjectors] = {tolerance2, tolerance2, tolerance2};
      for (int p = 0; p < projectors; ++p) {
        for (int q = 0; q < projectors; ++q) {
          if (q == p) {
            continue;
          }
          const std::int32_t apart = wrapDistance(predicted2(p), predicted2(q));
          tolerance[p] = apart / 2 < tolerance[p] ? apart / 2 : tolerance[p];
        }
      }
      for (int round = 0; round < projectors; ++round) {
        int bestP = -1;
        int bestL = -1;
        std::int32_t bestDiff = 65536;
        for (int p = 0; p < projectors; ++p) {
          if (assigned[p]) {
            continue;
          }
          for (int l = 0; l < lobeCount; ++l) {
            if (lobes[l].used) {
              continue;
            }
            const std::int32_t diff = wrapDistance(lobes[l].angle2, predicted2(p));
            if (diff <= tolerance[p] && diff < bestDiff) {
              bestDiff = diff;
              bestP = p;
              bestL = l;
            }
          }
        }
        if (bestP < 0) {
          break;
        }
        bestL = preferTileLobe(lobes, lobeCount, bestL, predicted2(bestP), tolerance[bestP]);
        assigned[bestP] = true;
        lobes[bestL].used = true;
        TileDirection& d = out[static_cast<std::size_t>(bestP) * tileCount + tile];
        d.angle = axisTowards(lobes[bestL].angle2, d.angle);  // d.angle: the prediction
        d.present = 1;
      }
    }
  }
}

void finishDirections(const DemuxLayout& layout, std::span<const std::uint32_t> tileHistograms,
                      std::span<const std::int32_t> tileMoments,
                      std::span<const std::uint16_t> predicted, std::span<TileDirection> out,
                      std::span<std::uint16_t> scratch) {
  growFoundTiles(layout, tileHistograms, tileMoments, predicted, out);
  // Twice: the second pass removes what clusters of stray tiles leave after the first.
  medianFilterTiles(layout, predicted, out, scratch);
  medianFilterTiles(layout, predicted, out, scratch);
  fillAbsentTiles(layout, predicted, out);
}

#if SMX_DEMUX_AVX2
SMX_AVX2_TWIN void avx2::matchTileLobes(const DemuxLayout& layout,
                                        std::span<const std::uint32_t> tileHistograms,
                                        std::span<const std::int32_t> tileMoments,
                                        std::span<const std::uint16_t> predicted,
                                        std::span<TileDirection> out, int firstTileRow,
                                        int endTileRow) {
  demux::matchTileLobes(layout, tileHistograms, tileMoments, predicted, out, firstTileRow,
                        endTileRow);
}

SMX_AVX2_TWIN void avx2::finishDirections(const DemuxLayout& layout,
                                          std::span<const std::uint32_t> tileHistograms,
                                          std::span<const std::int32_t> tileMoments,
                                          std::span<const std::uint16_t> predicted,
                                          std::span<TileDirection> out,
                                          std::span<std::uint16_t> scratch) {
  demux::finishDirections(layout, tileHistograms, tileMoments, predicted, out, scratch);
}
#endif

}  // namespace smx::algo::demux
