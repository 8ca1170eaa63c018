// Reference of stage 2b (demux_reference.hpp): per tile the window histogram summed directly,
// its lobes, their assignment to projectors, then the clean-up of the tile field, each step a
// plain loop. Schedule: schedule/directions.cpp (window sums sliding along the tile row, lobe
// windows from their halves' maxima, the median by a selection network).
#include <algorithm>
#include <cstdint>
#include <utility>

#include "demux_reference.hpp"

namespace smx::algo::demux::reference {

namespace {

constexpr int kRefineBins = 2;  // mean shift over ±2 bins
constexpr int kShareBins = 3;   // a lobe's mass: ±3 bins
constexpr int kMaxLobes = 8;    // one per angle window
constexpr std::uint64_t kTileMassFactor = 3;
constexpr int kFillRadius = 2;
constexpr int kGrowPasses = 6;
constexpr std::int32_t kGrowTolerance2 = 2 * 20 * 65536 / 360;  // 20° of orientation, doubled

struct Histogram {
  std::uint32_t weights[kBins] = {};
  std::int64_t moments[kBins] = {};
};

struct Lobe {
  std::uint16_t angle2 = 0;  // refined doubled angle
  bool used = false;         // taken, or below the minimum share of the window
  std::uint32_t tileMass = 0;
};

struct Lobes {
  Lobe lobe[kMaxLobes];
  int count = 0;
};

std::int32_t wrapDistance(std::uint16_t a, std::uint16_t b) {
  const std::int32_t d = wrapDiff(a, b);
  return d < 0 ? -d : d;
}

// The half of doubled angle angle2 within a quarter turn of `reference`.
std::uint16_t axisTowards(std::uint16_t angle2, std::uint16_t reference) {
  auto angle = static_cast<std::uint16_t>(angle2 >> 1U);
  const std::int32_t off = wrapDiff(angle, reference);
  return off > 16384 || off < -16384 ? static_cast<std::uint16_t>(angle + 32768U) : angle;
}

std::uint16_t doubled(std::uint16_t angle) {
  return static_cast<std::uint16_t>(angle << 1U);
}

class Tiles {
 public:
  explicit Tiles(const DemuxLayout& layout) : tilesX_(layout.tilesX()), tilesY_(layout.tilesY()) {}
  [[nodiscard]] std::size_t index(int tx, int ty) const {
    return static_cast<std::size_t>(ty) * static_cast<std::size_t>(tilesX_) +
           static_cast<std::size_t>(tx);
  }
  // visit(tile index) for each tile within ±radius of (tx, ty) inside the grid, row-major.
  template <class Visit>
  void around(int tx, int ty, int radius, Visit visit) const {
    for (int j = ty - radius; j <= ty + radius; ++j) {
      for (int i = tx - radius; i <= tx + radius; ++i) {
        if (i >= 0 && j >= 0 && i < tilesX_ && j < tilesY_) {
          visit(index(i, j));
        }
      }
    }
  }
  [[nodiscard]] int x() const { return tilesX_; }
  [[nodiscard]] int y() const { return tilesY_; }

 private:
  int tilesX_;
  int tilesY_;
};

// The window histogram: the sum over the tiles within ±windowTiles/2.
Histogram windowOf(const Tiles& tiles, int tx, int ty, int radius,
                   std::span<const std::uint32_t> weights, std::span<const std::int32_t> moments) {
  Histogram sum;
  tiles.around(tx, ty, radius, [&](std::size_t t) {
    for (int k = 0; k < kBins; ++k) {
      sum.weights[k] += weights[t * kBins + static_cast<std::size_t>(k)];
      sum.moments[k] += moments[t * kBins + static_cast<std::size_t>(k)];
    }
  });
  return sum;
}

// The peak refined by two mean-shift steps: the weighted mean doubled angle of the samples in
// the bins within ±kRefineBins of the current centre (each bin's samples from its weight and
// first moment).
std::uint16_t refine(int peakBin, const Histogram& hist) {
  std::int32_t centre = peakBin * kBinRaw;
  for (int step = 0; step < 2; ++step) {
    const std::int32_t centreBin = (centre + kBinRaw / 2) >> 10;  // floor division by kBinRaw
    std::int64_t moment = 0;
    std::uint64_t mass = 0;
    for (int k = centreBin - kRefineBins; k <= centreBin + kRefineBins; ++k) {
      const auto bin = static_cast<std::size_t>(k & (kBins - 1));
      mass += hist.weights[bin];
      moment += std::int64_t{hist.weights[bin]} * (k * kBinRaw - centre) + hist.moments[bin];
    }
    if (mass == 0) {
      break;
    }
    centre += static_cast<std::int32_t>(moment / static_cast<std::int64_t>(mass));
  }
  return static_cast<std::uint16_t>(static_cast<std::uint32_t>(centre) & 0xFFFFU);
}

// §3.2: an angle window of π/2 (16 bins) stepped by π/4 (8 bins); its first maximum is a lobe
// unless it lies at the window's edge. Each lobe refined; its share is the window histogram
// within ±kShareBins of the refined peak, its tile mass the centre tile's own there.
Lobes findLobes(const Histogram& window, const std::uint32_t* own, std::uint64_t minSharePct) {
  Lobes lobes;
  std::uint64_t total = 0;
  for (const std::uint32_t weight : window.weights) {
    total += weight;
  }
  if (total == 0) {
    return lobes;
  }
  int peaks[kMaxLobes] = {};
  for (int start = 0; start < kBins; start += kBins / 8) {
    int best = start;
    for (int k = start + 1; k < start + kBins / 4; ++k) {
      best = window.weights[k % kBins] > window.weights[best % kBins] ? k : best;
    }
    const int bin = best % kBins;
    if (best == start || best == start + kBins / 4 - 1 || window.weights[bin] == 0) {
      continue;
    }
    bool seen = false;
    for (int l = 0; l < lobes.count; ++l) {
      seen = seen || peaks[l] == bin;
    }
    if (seen) {
      continue;
    }
    peaks[lobes.count] = bin;
    Lobe& lobe = lobes.lobe[lobes.count++];
    lobe.angle2 = refine(bin, window);
    const int centre = ((lobe.angle2 + kBinRaw / 2) / kBinRaw) % kBins;
    std::uint64_t mass = 0;
    for (int k = centre - kShareBins; k <= centre + kShareBins; ++k) {
      mass += window.weights[(k + kBins) % kBins];
      lobe.tileMass += own[(k + kBins) % kBins];
    }
    lobe.used = mass * 100 < minSharePct * total;
  }
  return lobes;
}

// One projector's tiles and their predictions.
struct Projector {
  std::span<TileDirection> tiles;
  std::span<const std::uint16_t> predicted;
  std::size_t index;
  std::size_t count;
  [[nodiscard]] std::uint16_t prediction(std::size_t t) const {
    return predicted[t * count + index];
  }
  [[nodiscard]] std::int32_t offset(std::size_t t) const {
    return wrapDiff(tiles[t].angle, prediction(t));
  }
  // Tile t's prediction shifted by the mean of n offsets summing to `sum` (n > 0).
  [[nodiscard]] std::uint16_t predictionShifted(std::size_t t, std::int32_t sum,
                                                std::int32_t n) const {
    return static_cast<std::uint16_t>(prediction(t) + static_cast<std::uint16_t>(sum / n));
  }
};

Projector projector(const DemuxLayout& layout, std::span<const std::uint16_t> predicted,
                    std::span<TileDirection> out, int p) {
  const std::size_t n = layout.tileCount();
  return {out.subspan(static_cast<std::size_t>(p) * n, n), predicted, static_cast<std::size_t>(p),
          static_cast<std::size_t>(layout.projectors)};
}

// Lobes assigned greedily, the closest (projector, lobe) pair within the projector's tolerance
// first; a lobe within the tolerance that the tile itself holds kTileMassFactor times more of
// wins over the closest.
void assignTile(const DemuxLayout& layout, std::span<const std::uint16_t> predicted,
                std::span<TileDirection> out, std::size_t tile, Lobes& lobes) {
  const int projectors = layout.projectors;
  const std::int32_t cap = layout.params.lobeToleranceDeg * 2 * 65536 / 360;
  std::uint16_t predicted2[kMaxProjectors] = {};
  std::int32_t tolerance[kMaxProjectors] = {};
  for (int p = 0; p < projectors; ++p) {
    const Projector pr = projector(layout, predicted, out, p);
    pr.tiles[tile] = {pr.prediction(tile), 0};
    predicted2[p] = doubled(pr.prediction(tile));
  }
  for (int p = 0; p < projectors; ++p) {
    tolerance[p] = cap;
    for (int q = 0; q < projectors; ++q) {
      if (q != p) {
        tolerance[p] = std::min(tolerance[p], wrapDistance(predicted2[p], predicted2[q]) / 2);
      }
    }
  }
  bool assigned[kMaxProjectors] = {};
  for (int round = 0; round < projectors; ++round) {
    int bestP = -1;
    int bestL = -1;
    std::int32_t bestDiff = 65536;
    for (int p = 0; p < projectors; ++p) {
      for (int l = 0; l < lobes.count; ++l) {
        const std::int32_t diff = wrapDistance(lobes.lobe[l].angle2, predicted2[p]);
        if (!assigned[p] && !lobes.lobe[l].used && diff <= tolerance[p] && diff < bestDiff) {
          bestDiff = diff;
          bestP = p;
          bestL = l;
        }
      }
    }
    if (bestP < 0) {
      return;
    }
    const int nearest = bestL;
    for (int l = 0; l < lobes.count; ++l) {
      const Lobe& lobe = lobes.lobe[l];
      if (!lobe.used && l != nearest &&
          wrapDistance(lobe.angle2, predicted2[bestP]) <= tolerance[bestP] &&
          std::uint64_t{lobe.tileMass} >
              kTileMassFactor * std::uint64_t{lobes.lobe[bestL].tileMass}) {
        bestL = l;
      }
    }
    assigned[bestP] = true;
    lobes.lobe[bestL].used = true;
    TileDirection& d = projector(layout, predicted, out, bestP).tiles[tile];
    d = {axisTowards(lobes.lobe[bestL].angle2, d.angle), 1};
  }
}

// Found tiles grow into absent ones, a ring per pass: an absent tile next to found ones takes
// its window lobe nearest their mean offset from the prediction, within kGrowTolerance2 and not
// nearer another projector's found direction. Tiles grown in a pass (2) count as found from the
// next (3, then 1); after the first pass only tiles next to the last ring are tried.
constexpr std::uint8_t kGrowing = 2;
constexpr std::uint8_t kGrown = 3;

// The unused lobe of tile t nearest `guess` within kGrowTolerance2 and no nearer another
// projector's direction found in the tile; −1 when there is none.
int growthLobe(const DemuxLayout& layout, std::span<const std::uint16_t> predicted,
               std::span<TileDirection> out, int p, std::size_t t, const Lobes& lobes,
               std::uint16_t guess) {
  int best = -1;
  std::int32_t bestDiff = kGrowTolerance2 + 1;
  for (int l = 0; l < lobes.count; ++l) {
    const std::int32_t diff = wrapDistance(lobes.lobe[l].angle2, doubled(guess));
    bool nearerOther = false;
    for (int q = 0; q < layout.projectors; ++q) {
      const TileDirection& other = projector(layout, predicted, out, q).tiles[t];
      nearerOther =
          nearerOther || (q != p && other.present != 0 &&
                          wrapDistance(lobes.lobe[l].angle2, doubled(other.angle)) <= diff);
    }
    if (!lobes.lobe[l].used && !nearerOther && diff < bestDiff) {
      bestDiff = diff;
      best = l;
    }
  }
  return best;
}

void grow(const DemuxLayout& layout, const Tiles& grid, std::span<const std::uint32_t> weights,
          std::span<const std::int32_t> moments, std::span<const std::uint16_t> predicted,
          std::span<TileDirection> out) {
  const auto minSharePct = static_cast<std::uint64_t>(layout.params.minLobeSharePct);
  for (int pass = 0; pass < kGrowPasses; ++pass) {
    bool grew = false;
    for (int p = 0; p < layout.projectors; ++p) {
      const Projector pr = projector(layout, predicted, out, p);
      for (int ty = 0; ty < grid.y(); ++ty) {
        for (int tx = 0; tx < grid.x(); ++tx) {
          const std::size_t t = grid.index(tx, ty);
          if (pr.tiles[t].present != 0) {
            continue;
          }
          std::int32_t sum = 0;
          std::int32_t count = 0;
          bool nextToNew = pass == 0;
          grid.around(tx, ty, 1, [&](std::size_t n) {
            const std::uint8_t present = pr.tiles[n].present;
            if (present == 1 || present == kGrown) {
              sum += pr.offset(n);
              ++count;
              nextToNew = nextToNew || present == kGrown;
            }
          });
          if (count == 0 || !nextToNew) {
            continue;
          }
          const std::uint16_t guess = pr.predictionShifted(t, sum, count);
          const Lobes lobes =
              findLobes(windowOf(grid, tx, ty, layout.params.windowTiles / 2, weights, moments),
                        weights.data() + t * kBins, minSharePct);
          const int best = growthLobe(layout, predicted, out, p, t, lobes, guess);
          if (best >= 0) {
            pr.tiles[t] = {axisTowards(lobes.lobe[best].angle2, guess), kGrowing};
            grew = true;
          }
        }
      }
    }
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

// Each found tile takes the median offset from the prediction over the found tiles of its 3×3
// neighbourhood (the upper median of an even count), all from the unfiltered field.
void median(const DemuxLayout& layout, const Tiles& grid, std::span<const std::uint16_t> predicted,
            std::span<TileDirection> out, std::span<std::uint16_t> scratch) {
  for (int p = 0; p < layout.projectors; ++p) {
    const Projector pr = projector(layout, predicted, out, p);
    for (int ty = 0; ty < grid.y(); ++ty) {
      for (int tx = 0; tx < grid.x(); ++tx) {
        const std::size_t t = grid.index(tx, ty);
        scratch[t] = pr.tiles[t].angle;
        if (pr.tiles[t].present == 0) {
          continue;
        }
        std::int32_t found[9] = {};
        int count = 0;
        grid.around(tx, ty, 1, [&](std::size_t n) {
          if (pr.tiles[n].present == 1) {
            found[count++] = pr.offset(n);
          }
        });
        for (int i = 1; i < count; ++i) {  // insertion sort
          for (int j = i; j > 0 && found[j - 1] > found[j]; --j) {
            std::swap(found[j - 1], found[j]);
          }
        }
        scratch[t] = static_cast<std::uint16_t>(pr.prediction(t) +
                                                static_cast<std::uint16_t>(found[count / 2]));
      }
    }
    for (std::size_t t = 0; t < pr.tiles.size(); ++t) {
      pr.tiles[t].angle = scratch[t];
    }
  }
}

// An absent tile takes the prediction shifted by the mean offset of the found tiles within
// ±kFillRadius.
void fillAbsent(const DemuxLayout& layout, const Tiles& grid,
                std::span<const std::uint16_t> predicted, std::span<TileDirection> out) {
  for (int p = 0; p < layout.projectors; ++p) {
    const Projector pr = projector(layout, predicted, out, p);
    for (int ty = 0; ty < grid.y(); ++ty) {
      for (int tx = 0; tx < grid.x(); ++tx) {
        const std::size_t t = grid.index(tx, ty);
        if (pr.tiles[t].present != 0) {
          continue;
        }
        std::int32_t sum = 0;
        std::int32_t count = 0;
        grid.around(tx, ty, kFillRadius, [&](std::size_t n) {
          if (pr.tiles[n].present == 1) {
            sum += pr.offset(n);
            ++count;
          }
        });
        if (count > 0) {
          pr.tiles[t].angle = pr.predictionShifted(t, sum, count);
        }
      }
    }
  }
}

}  // namespace

void directions(const DemuxLayout& layout, std::span<const std::uint32_t> weights,
                std::span<const std::int32_t> moments, std::span<const std::uint16_t> predicted,
                std::span<TileDirection> out, std::span<std::uint16_t> scratch) {
  const Tiles grid(layout);
  const auto minSharePct = static_cast<std::uint64_t>(layout.params.minLobeSharePct);
  for (int ty = 0; ty < grid.y(); ++ty) {
    for (int tx = 0; tx < grid.x(); ++tx) {
      const std::size_t t = grid.index(tx, ty);
      Lobes lobes =
          findLobes(windowOf(grid, tx, ty, layout.params.windowTiles / 2, weights, moments),
                    weights.data() + t * kBins, minSharePct);
      assignTile(layout, predicted, out, t, lobes);
    }
  }
  grow(layout, grid, weights, moments, predicted, out);
  median(layout, grid, predicted, out, scratch);  // twice: the second removes what clusters of
  median(layout, grid, predicted, out, scratch);  // stray tiles leave after the first
  fillAbsent(layout, grid, predicted, out);
}

}  // namespace smx::algo::demux::reference
