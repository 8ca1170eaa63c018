// The demultiplexer: working memory carved from the arena at create() (the only place that
// takes memory), the stages of demux_kernels.hpp run in order per frame.
#include "smx/algo/demux.hpp"

#include <algorithm>
#include <cstdint>
#include <span>

#include "demux_kernels.hpp"
#include "smx/algo/fixed_math.hpp"

namespace smx::algo {

namespace demux {

void UnitTable::fill() {
  for (std::size_t i = 0; i < kEntries; ++i) {
    cos_[i] = algo::cos(BinAngle{static_cast<std::uint16_t>(i * (65536 / kEntries))});
  }
}

const Kernels& baselineKernels() {
  static constexpr Kernels kBaseline{smoothChannels,   histogramTiles,        matchTileLobes,
                                     finishDirections, interpolateDirections, separate,
                                     detectBoundaries};
  return kBaseline;
}

const Kernels& fastestKernels() {
#if SMX_DEMUX_AVX2
  static constexpr Kernels kAvx2{avx2::smoothChannels,        avx2::histogramTiles,
                                 avx2::matchTileLobes,        avx2::finishDirections,
                                 avx2::interpolateDirections, avx2::separate,
                                 avx2::detectBoundaries};
  if (__builtin_cpu_supports("avx2")) {
    return kAvx2;
  }
#endif
  return baselineKernels();
}

}  // namespace demux

namespace {

Result<void> validate(const DemuxLayout& l, int lanes) {
  const DemuxParams& p = l.params;
  if (l.width < 8 || l.height < 8 || l.width > 8192 || l.height > 8192) {
    return fail(Errc::kInvalidArgument, "demux: image size must be 8 to 8192 pixels per side");
  }
  if (l.projectors < 1 || l.projectors > kMaxProjectors) {
    return fail(Errc::kInvalidArgument, "demux: 1 to 3 projectors");
  }
  if (lanes < 1 || lanes > l.projectors) {
    return fail(Errc::kInvalidArgument, "demux: 1 lane to one per projector");
  }
  if (p.tilePx < 4 || p.tilePx > 64 || p.windowTiles < 1 || p.windowTiles > 9 ||
      p.windowTiles % 2 == 0 || p.histogramStride < 1 || p.histogramStride > 8 ||
      p.smoothPasses < 0 || p.smoothPasses > 3 ||
      (p.tilePx / p.histogramStride) * (p.tilePx / p.histogramStride) > 64) {
    return fail(Errc::kInvalidArgument,
                "demux: tilePx 4 to 64, windowTiles odd 1 to 9, histogramStride 1 to 8, "
                "smoothPasses 0 to 3, (tilePx / histogramStride)^2 <= 64");
  }
  if (p.lobeToleranceDeg < 1 || p.lobeToleranceDeg > 45 || p.minLobeSharePct < 0 ||
      p.minLobeSharePct > 100 || p.minGradientGrey < 0 || p.minGradientGrey > 255 ||
      p.minStrengthPermille < 0 || p.minStrengthPermille > 16000 || p.minContrastGrey < 0 ||
      p.minContrastGrey > 255) {
    return fail(Errc::kInvalidArgument, "demux: a threshold is out of range");
  }
  return {};
}

}  // namespace

template <class Carver>
Result<void> Demultiplexer::carve(Carver& carver) {
  const DemuxLayout& l = layout_;
  const std::size_t tiles = l.tileCount();
  const auto projectors = static_cast<std::size_t>(l.projectors);
  Result<void> ok;
  const auto step = [&ok](Result<void> r) {
    if (ok && !r) {
      ok = r;
    }
  };
  step(carveSpan(carver, predicted_, tiles * projectors));
  step(carveSpan(carver, units_, 1));
  step(carveSpan(carver, columns_, static_cast<std::size_t>(l.width)));
  step(carveSpan(carver, rows_, static_cast<std::size_t>(l.height)));
  step(
      carveSpan(carver, rowScratch_, demux::kSmoothRowScratch * static_cast<std::size_t>(l.width)));
  step(carveSpan(carver, filterRows_,
                 demux::RowBlock<std::int32_t>::valuesFor(demux::kFilterRows, l.width)));
  step(carveSpan(carver, workRows_,
                 demux::RowBlock<std::int16_t>::valuesFor(demux::kSharedWorkRows, l.width)));
  step(carveSpan(carver, tileHistograms_, tiles * demux::kBins));
  step(carveSpan(carver, tileMoments_, tiles * demux::kBins));
  step(carveSpan(carver, tileColourSums_, tiles * 3));
  step(carveSpan(carver, tileInverseColour_, tiles * 3));
  step(carveSpan(carver, tileDirections_, tiles * projectors));
  step(carveSpan(carver, tileScratch_, tiles));
  for (auto& plane : smoothed_) {
    step(carveImage(carver, plane, l.width, l.height));
  }
  // With one lane the last projector's separated planes take smoothed_'s memory: 3 planes
  // less. Lanes separate bands of rows at once, each reading the rows beside its band.
  const std::size_t ownPlanes = lanes_ == 1 ? projectors - 1 : projectors;
  if (ownPlanes < projectors) {
    separated_[projectors - 1] = smoothed_;
  }
  for (std::size_t p = 0; p < ownPlanes; ++p) {
    for (auto& plane : separated_[p]) {
      step(carveImage(carver, plane, l.width, l.height));
    }
  }
  for (int lane = 0; lane < lanes_; ++lane) {
    LaneScratch& scratch = laneScratch_[static_cast<std::size_t>(lane)];
    if (lane == 0) {
      scratch.filterRows = filterRows_;
      scratch.workRows = workRows_;
    } else {
      step(carveSpan(carver, scratch.filterRows,
                     demux::RowBlock<std::int32_t>::valuesFor(demux::kFilterRows, l.width)));
      step(carveSpan(carver, scratch.workRows,
                     demux::RowBlock<std::int16_t>::valuesFor(demux::kSharedWorkRows, l.width)));
    }
    step(carveImage(carver, scratch.strength, l.width, l.height));
    step(carveImage(carver, scratch.derivativeStrength, l.width, l.height));
  }
  for (std::size_t p = 0; p < projectors; ++p) {
    step(carveImage(carver, order_[p], l.width, l.height));
    step(carveImage(carver, boundaries_[p], l.width, l.height));
    step(carveImage(carver, directions_[p], l.width, l.height));
  }
  return ok;
}

Result<std::size_t> Demultiplexer::workspaceBytes(const DemuxLayout& layout, int lanes) {
  if (auto ok = validate(layout, lanes); !ok) {
    return std::unexpected(ok.error());
  }
  Demultiplexer d;
  d.layout_ = layout;
  d.lanes_ = lanes;
  ArenaSizer sizer;
  if (auto ok = d.carve(sizer); !ok) {
    return std::unexpected(ok.error());
  }
  return sizer.bytes();
}

Result<Demultiplexer> Demultiplexer::create(const DemuxLayout& layout,
                                            std::span<const std::uint16_t> predictedAngles,
                                            Arena& arena, DemuxSchedule schedule, int lanes) {
  if (auto ok = validate(layout, lanes); !ok) {
    return std::unexpected(ok.error());
  }
  if (predictedAngles.size() != layout.tileCount() * static_cast<std::size_t>(layout.projectors)) {
    return fail(Errc::kSizeMismatch, "demux: predicted angles must be tileCount x projectors");
  }
  Demultiplexer d;
  d.layout_ = layout;
  d.lanes_ = lanes;
  const Arena::Marker start = arena.mark();
  if (auto ok = d.carve(arena); !ok) {
    arena.rewind(start);
    return std::unexpected(ok.error());
  }
  for (std::size_t i = 0; i < predictedAngles.size(); ++i) {
    d.predicted_[i] = predictedAngles[i];
  }
  d.kernels_ =
      schedule == DemuxSchedule::kAutomatic ? &demux::fastestKernels() : &demux::baselineKernels();
  d.units_[0].fill();
  demux::tileInterpolation(layout.width, layout.params.tilePx, layout.tilesX(), d.columns_);
  demux::tileInterpolation(layout.height, layout.params.tilePx, layout.tilesY(), d.rows_);
  return d;
}

Result<void> Demultiplexer::run(ConstRgbView image) {
  SerialJobs serial;
  return run(image, serial);
}

Result<void> Demultiplexer::run(ConstRgbView image, JobRunner& jobs) {
  if (image.width() != layout_.width || image.height() != layout_.height) {
    return fail(Errc::kSizeMismatch, "demux: image size differs from the layout");
  }
  const DemuxParams& p = layout_.params;
  kernels_->smooth(image, smoothed_, p.smoothPasses, rowScratch_);
  demux::sumTileColours(smoothed_, p.tilePx, tileColourSums_);
  demux::inverseTileColours(tileColourSums_, layout_, p.normaliseColour, tileInverseColour_);
  if (!fixedDirections_) {
    // separate()'s filter rows are free until it runs.
    static_assert(demux::kHistogramRows <= demux::kFilterRows);
    const int tilesY = layout_.tilesY();
    auto band = [&](int b) {
      kernels_->histogram(smoothed_, layout_,
                          demux::RowBlock<std::int32_t>(
                              laneScratch_[static_cast<std::size_t>(b)].filterRows, layout_.width),
                          tileHistograms_, tileMoments_, b * tilesY / lanes_,
                          (b + 1) * tilesY / lanes_);
    };
    jobs.forEach(lanes_, band);
    // Each tile's window reaches into the neighbouring bands: the matching waits for all of them.
    auto lobes = [&](int b) {
      kernels_->lobes(layout_, tileHistograms_, tileMoments_, predicted_, tileDirections_,
                      b * tilesY / lanes_, (b + 1) * tilesY / lanes_);
    };
    jobs.forEach(lanes_, lobes);
    kernels_->finish(layout_, tileHistograms_, tileMoments_, predicted_, tileDirections_,
                     tileScratch_);
  }
  const auto projectors = static_cast<std::size_t>(layout_.projectors);
  static_assert(demux::kInterpolationRows <= demux::kFilterRows);
  // Per band of rows: the directions there (separation reads only its own rows'), then every
  // projector separated in one sweep (the derivatives are shared); then the boundaries.
  auto separation = [&](int b) {
    const LaneScratch& scratch = laneScratch_[static_cast<std::size_t>(b)];
    const demux::RowRange band{b * layout_.height / lanes_, (b + 1) * layout_.height / lanes_};
    const std::span<const DirectionPlane> directions(directions_.data(), projectors);
    kernels_->interpolation(layout_, tileDirections_, columns_, rows_,
                            demux::RowBlock<std::int32_t>(scratch.filterRows, layout_.width),
                            directions, band);
    kernels_->separation(smoothed_, layout_, tileDirections_, columns_, rows_, units_[0],
                         demux::RowBlock<std::int32_t>(scratch.filterRows, layout_.width),
                         demux::RowBlock<std::int16_t>(scratch.workRows, layout_.width), directions,
                         std::span<const demux::Planes3>(separated_.data(), projectors),
                         std::span<const ImageView<std::uint8_t>>(order_.data(), projectors), band);
  };
  jobs.forEach(lanes_, separation);
  // separate() is done with its working rows: they hold detectBoundaries()' ring.
  const demux::TileColours colours{tileInverseColour_, layout_.tilesX(), columns_, rows_};
  auto lane = [&](int l) {
    const LaneScratch& scratch = laneScratch_[static_cast<std::size_t>(l)];
    for (auto q = static_cast<std::size_t>(l); q < projectors;
         q += static_cast<std::size_t>(lanes_)) {
      kernels_->boundaries(separated_[q], order_[q], directions_[q], units_[0], colours,
                           demux::minStrengthQ11(p),
                           demux::RowBlock<std::int16_t>(scratch.workRows, layout_.width),
                           {scratch.strength, scratch.derivativeStrength}, boundaries_[q]);
    }
  };
  jobs.forEach(lanes_, lane);
  return {};
}

Result<void> Demultiplexer::fixTileDirections(std::span<const TileDirection> tiles) {
  if (tiles.size() != tileDirections_.size()) {
    return fail(Errc::kSizeMismatch,
                "demux: fixed tile directions need projectors x tiles entries");
  }
  std::ranges::copy(tiles, tileDirections_.begin());
  fixedDirections_ = true;
  return {};
}

ConstBoundaryPlane Demultiplexer::boundaries(int projector) const {
  return boundaries_[static_cast<std::size_t>(projector)];
}

ConstDirectionPlane Demultiplexer::directions(int projector) const {
  return directions_[static_cast<std::size_t>(projector)];
}

std::span<const TileDirection> Demultiplexer::tileDirections(int projector) const {
  return tileDirections_.subspan(static_cast<std::size_t>(projector) * layout_.tileCount(),
                                 layout_.tileCount());
}

ImageView<const std::int16_t> Demultiplexer::separated(int projector, int channel) const {
  return separated_[static_cast<std::size_t>(projector)][static_cast<std::size_t>(channel)];
}

}  // namespace smx::algo
