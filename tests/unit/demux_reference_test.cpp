// Algorithm beside schedule: each per-frame stage of the demultiplexer has a plain scalar
// reference (src/frame/demux/reference) and the schedule run() calls (src/frame/demux/schedule;
// on x86-64 a baseline and an AVX2 build of it). Given the same inputs, every built schedule
// must give the reference's output bit for bit. The inputs of each stage are the reference
// outputs of the stages before it, on noisy frames of 1, 2 and 3 superposed patterns computed
// here (on every target) and, in the host's optimised build, on the simulator's renders of the
// sphere (2 projectors) and the plane (3 projectors) at 640 × 480.
#include "demux_reference.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

#include "demux_kernels.hpp"
#include "smx/algo/demux.hpp"
#include "smx/algo/fixed_math.hpp"
#include "synthetic_stripes.hpp"

#if SMX_REFERENCE_SIM_SCENES
#include "smx/algo/encoding_prediction.hpp"
#include "smx/eval/sim_frame.hpp"
#endif

namespace smx::algo {
namespace {

using test::SyntheticPattern;
namespace ref = demux::reference;

// A plane over its own memory.
template <class T>
struct OwnedPlane {
  std::vector<T> pixels;
  ImageView<T> view;

  OwnedPlane(int w, int h, T fill = T{})
      : pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill),
        view(*ImageView<T>::packed(pixels, w, h)) {}
  // Moving keeps the memory (and the view valid); a copy would not.
  OwnedPlane(OwnedPlane&&) noexcept = default;
  OwnedPlane(const OwnedPlane&) = delete;
  OwnedPlane& operator=(const OwnedPlane&) = delete;
  OwnedPlane& operator=(OwnedPlane&&) = delete;
  ~OwnedPlane() = default;
};

// Three planes over their own memory, and their views. Filled with a value no stage writes
// there, so that a pixel a schedule leaves unwritten differs.
struct OwnedPlanes3 {
  std::vector<std::vector<std::int16_t>> memory;
  demux::Planes3 views;

  OwnedPlanes3(int w, int h) : memory(3) {
    for (std::size_t c = 0; c < 3; ++c) {
      memory[c].assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0x5A5A);
      views[c] = *ImageView<std::int16_t>::packed(memory[c], w, h);
    }
  }
};

// A frame: the superposed patterns over a surface whose colour varies, with noise of σ 8 grey
// levels, and the predicted directions per tile. Widths are no multiple of any vector length,
// so the schedules' loop tails run.
struct Frame {
  std::string name;
  DemuxLayout layout;
  std::vector<Rgb8> image;
  std::vector<std::uint16_t> predicted;  // tile-major, projectors per tile
};

std::vector<Rgb8> noisyImage(const std::vector<SyntheticPattern>& patterns, int w, int h,
                             bool lastOnRightHalfOnly, unsigned seed) {
  std::vector<Rgb8> image = test::superpose(patterns, w, h);
  if (lastOnRightHalfOnly) {
    // The last pattern absent from the left half: tiles without its lobe, which the direction
    // stage fills from their neighbours.
    const std::vector<SyntheticPattern> fewer(patterns.begin(), patterns.end() - 1);
    const std::vector<Rgb8> without = test::superpose(fewer, w, h);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w / 2; ++x) {
        const auto i = static_cast<std::size_t>(y * w + x);
        image[i] = without[i];
      }
    }
  }
  test::colourAndNoise(image, w, h, seed);
  return image;
}

// Predictions 4° off the patterns, except in the top tile row, where the first projector's are
// 40° off (beyond the tolerance): its lobe is found there only by growing from below.
Frame makeFrame(std::string name, const std::vector<SyntheticPattern>& patterns, int w, int h,
                DemuxParams params, bool lastOnRightHalfOnly) {
  Frame f{std::move(name), {w, h, static_cast<int>(patterns.size()), params}, {}, {}};
  f.image = noisyImage(patterns, w, h, lastOnRightHalfOnly, 7);
  for (std::size_t t = 0; t < f.layout.tileCount(); ++t) {
    const bool top = t < static_cast<std::size_t>(f.layout.tilesX());
    for (std::size_t p = 0; p < patterns.size(); ++p) {
      const double off = top && p == 0 && patterns.size() < 3 ? 40.0 : 4.0;
      f.predicted.push_back(BinAngle::fromDegrees(patterns[p].angleDeg + off).raw);
    }
  }
  return f;
}

#if SMX_REFERENCE_SIM_SCENES
// Camera 0 of an example rig viewing a named scene, predictions at the accuracy tests' nominal
// depth (0.75 m, the scenes stand at 0.9 m).
Frame renderedFrame(std::string name, const std::string& rigFile, const std::string& scene) {
  eval::SimRequest request;
  request.rigFile = rigFile;
  request.scene = scene;
  request.supersampling = 1;  // one sample per pixel: the stages see the same kind of image, sooner
  const eval::SimFrame sim = eval::renderSimFrame(request);
  Frame f{std::move(name),
          {sim.image.width, sim.image.height, static_cast<int>(sim.rig.projectors.size()), {}},
          sim.image.pixels,
          {}};
  f.predicted = *predictEncodingAngles(sim.rig, 0, f.layout, 0.75);
  return f;
}
#endif

const std::vector<Frame>& frames() {
  static const std::vector<Frame> kFrames = [] {
    DemuxParams other;  // the other code paths: tiles of 6, every pixel sampled, 2 passes
    other.tilePx = 6;
    other.histogramStride = 1;
    other.windowTiles = 5;
    other.smoothPasses = 2;
    other.normaliseColour = false;
    std::vector<Frame> f;
    f.push_back(makeFrame("1Pattern", {{30, 4.5}}, 131, 67, {}, false));
    f.push_back(makeFrame("2Patterns", {{0, 4.5}, {70, 4.5}}, 211, 97, {}, true));
    f.push_back(makeFrame("3Patterns", {{0, 5.0}, {60, 5.0}, {120, 5.0}}, 211, 97, {}, false));
    f.push_back(makeFrame("2PatternsOtherParams", {{20, 5.0}, {100, 5.0}}, 149, 83, other, true));
#if SMX_REFERENCE_SIM_SCENES
    f.push_back(renderedFrame("SphereRig2Proj", "rig_2proj_1cam.json", "sphere"));
    f.push_back(renderedFrame("PlaneRig3Proj", "rig_3proj_1cam.json", "plane"));
#endif
    return f;
  }();
  return kFrames;
}

// Every build of the schedules: the baseline, and the AVX2 twins where the CPU runs them.
struct Schedule {
  std::string name;
  const demux::Kernels* kernels;
};

std::vector<Schedule> schedules() {
  std::vector<Schedule> s{{"baseline", &demux::baselineKernels()}};
  if (&demux::fastestKernels() != &demux::baselineKernels()) {
    s.push_back({"avx2", &demux::fastestKernels()});
  }
  return s;
}

// The stages' reference outputs for a frame: each stage's inputs.
struct Stages {
  const Frame& frame;
  int w;
  int h;
  ConstRgbView image;
  demux::UnitTable units;
  std::vector<demux::TileInterp> columns;
  std::vector<demux::TileInterp> rows;
  OwnedPlanes3 smoothed;
  OwnedPlane<std::int16_t> scratch;
  std::vector<std::uint32_t> colourSums;
  std::vector<std::uint32_t> inverse;
  std::vector<std::uint32_t> weights;
  std::vector<std::int32_t> moments;
  std::vector<TileDirection> tiles;
  std::vector<std::uint16_t> tileScratch;
  std::vector<OwnedPlane<std::uint16_t>> directions;
  std::vector<OwnedPlanes3> separated;
  std::vector<OwnedPlane<std::uint8_t>> order;

  explicit Stages(const Frame& f)
      : frame(f),
        w(f.layout.width),
        h(f.layout.height),
        image(*ConstRgbView::packed(f.image, w, h)),
        columns(static_cast<std::size_t>(w)),
        rows(static_cast<std::size_t>(h)),
        smoothed(w, h),
        scratch(w, h),
        colourSums(f.layout.tileCount() * 3),
        inverse(f.layout.tileCount() * 3),
        weights(f.layout.tileCount() * demux::kBins),
        moments(f.layout.tileCount() * demux::kBins),
        tiles(f.layout.tileCount() * static_cast<std::size_t>(f.layout.projectors)),
        tileScratch(f.layout.tileCount()) {
    const DemuxLayout& l = f.layout;
    units.fill();
    demux::tileInterpolation(w, l.params.tilePx, l.tilesX(), columns);
    demux::tileInterpolation(h, l.params.tilePx, l.tilesY(), rows);
    ref::smooth(image, l.params.smoothPasses, smoothed.views, scratch.view);
    demux::sumTileColours(smoothed.views, l.params.tilePx, colourSums);
    demux::inverseTileColours(colourSums, l, l.params.normaliseColour, inverse);
    ref::histogram(smoothed.views, l, weights, moments);
    ref::directions(l, weights, moments, f.predicted, tiles, tileScratch);
    directions.reserve(static_cast<std::size_t>(l.projectors));
    separated.reserve(static_cast<std::size_t>(l.projectors));
    order.reserve(static_cast<std::size_t>(l.projectors));
    for (int p = 0; p < l.projectors; ++p) {
      directions.emplace_back(w, h);
      separated.emplace_back(w, h);
      order.emplace_back(w, h, std::uint8_t{9});
    }
    ref::interpolation(l, tiles, directionViews());
    ref::separation(smoothed.views, l, tiles, units, constDirectionViews(), separatedViews(),
                    orderViews());
  }

  [[nodiscard]] std::vector<DirectionPlane> directionViews() const {
    std::vector<DirectionPlane> v;
    for (const auto& d : directions) {
      v.push_back(d.view);
    }
    return v;
  }
  [[nodiscard]] std::vector<ConstDirectionPlane> constDirectionViews() const {
    std::vector<ConstDirectionPlane> v;
    for (const auto& d : directions) {
      v.emplace_back(d.view);
    }
    return v;
  }
  [[nodiscard]] std::vector<demux::Planes3> separatedViews() const {
    std::vector<demux::Planes3> v;
    for (const auto& s : separated) {
      v.push_back(s.views);
    }
    return v;
  }
  [[nodiscard]] std::vector<ImageView<std::uint8_t>> orderViews() const {
    std::vector<ImageView<std::uint8_t>> v;
    for (const auto& o : order) {
      v.push_back(o.view);
    }
    return v;
  }
};

// The first pixel at which two planes differ, as a message; empty when equal.
template <class T, class U>
std::string firstDifference(ImageView<T> a, ImageView<U> b) {
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      if (std::memcmp(&a(x, y), &b(x, y), sizeof(T)) != 0) {
        return "first difference at (" + std::to_string(x) + ", " + std::to_string(y) + ")";
      }
    }
  }
  return {};
}

template <class T>
std::string firstDifference(const std::vector<T>& a, const std::vector<T>& b) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::memcmp(&a[i], &b[i], sizeof(T)) != 0) {
      return "first difference at index " + std::to_string(i);
    }
  }
  return a.size() == b.size() ? std::string{} : "sizes differ";
}

template <class T>
std::vector<T> rowMemory(std::size_t rows, int width) {
  return std::vector<T>(demux::RowBlock<T>::valuesFor(rows, width));
}

// Given each frame, when the reference and each schedule smooth it (0, 1 and 2 passes), then the
// planes are equal.
void checkSmooth(const Frame& frame) {
  const Frame& f = frame;
  const int w = f.layout.width;
  const int h = f.layout.height;
  const ConstRgbView image = *ConstRgbView::packed(f.image, w, h);
  for (int passes = 0; passes <= 2; ++passes) {
    OwnedPlanes3 expected(w, h);
    OwnedPlane<std::int16_t> scratch(w, h);
    ref::smooth(image, passes, expected.views, scratch.view);
    for (const Schedule& s : schedules()) {
      OwnedPlanes3 got(w, h);
      std::vector<std::int16_t> rowScratch(demux::kSmoothRowScratch * static_cast<std::size_t>(w));
      s.kernels->smooth(image, got.views, passes, rowScratch);
      for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_EQ(firstDifference(expected.views[c], got.views[c]), "")
            << s.name << ", " << passes << " passes, channel " << c;
      }
    }
  }
}

// Given the smoothed planes, the tile histograms are equal and not empty.
void checkHistogram(const Frame& frame) {
  const Stages in(frame);
  std::uint64_t total = 0;
  for (const std::uint32_t w : in.weights) {
    total += w;
  }
  EXPECT_GT(total, 0U);
  // Whole, and in three bands of tile rows (as lanes run it): each band writes its tiles only.
  const int tilesY = in.frame.layout.tilesY();
  for (const Schedule& s : schedules()) {
    for (const int bands : {1, 3}) {
      std::vector<std::uint32_t> weights(in.weights.size(), 1);
      std::vector<std::int32_t> moments(in.moments.size(), 1);
      auto rows = rowMemory<std::int32_t>(demux::kHistogramRows, in.w);
      for (int b = 0; b < bands; ++b) {
        s.kernels->histogram(in.smoothed.views, in.frame.layout,
                             demux::RowBlock<std::int32_t>(rows, in.w), weights, moments,
                             b * tilesY / bands, (b + 1) * tilesY / bands);
      }
      EXPECT_EQ(firstDifference(in.weights, weights), "") << s.name << ", " << bands << " bands";
      EXPECT_EQ(firstDifference(in.moments, moments), "") << s.name << ", " << bands << " bands";
    }
  }
}

// Given the tile histograms, every projector's tile directions and presence are equal, and
// some tiles found the lobes (and on the frames where a pattern covers half of the image, some
// did not).
void checkDirections(const Frame& frame) {
  const Stages in(frame);
  std::size_t found = 0;
  for (const TileDirection& d : in.tiles) {
    found += d.present;
  }
  EXPECT_GT(found, in.tiles.size() / 3);
  // The matching whole, and in three bands of tile rows (as lanes run it).
  const int tilesY = in.frame.layout.tilesY();
  for (const Schedule& s : schedules()) {
    for (const int bands : {1, 3}) {
      std::vector<TileDirection> got(in.tiles.size(), TileDirection{1, 7});
      std::vector<std::uint16_t> scratch(in.tileScratch.size());
      for (int b = 0; b < bands; ++b) {
        s.kernels->lobes(in.frame.layout, in.weights, in.moments, in.frame.predicted, got,
                         b * tilesY / bands, (b + 1) * tilesY / bands);
      }
      s.kernels->finish(in.frame.layout, in.weights, in.moments, in.frame.predicted, got, scratch);
      for (std::size_t t = 0; t < got.size(); ++t) {
        EXPECT_EQ(got[t].angle, in.tiles[t].angle)
            << s.name << ", " << bands << " bands, tile " << t;
        EXPECT_EQ(got[t].present, in.tiles[t].present)
            << s.name << ", " << bands << " bands, tile " << t;
      }
    }
  }
}

// Given the tile directions, every projector's direction plane is equal, whether the schedule
// interpolates the image in one band or in bands of uneven heights, each with working rows of its
// own (one band's edge inside a tile row's band of rows).
void checkInterpolation(const Frame& frame) {
  const Stages in(frame);
  const std::vector<std::vector<int>> splits = {{0, in.h}, {0, 1, 3, in.h / 3 + 1, in.h}};
  for (const Schedule& s : schedules()) {
    for (const std::vector<int>& edges : splits) {
      std::vector<OwnedPlane<std::uint16_t>> got;
      std::vector<DirectionPlane> views;
      got.reserve(in.directions.size());
      for (std::size_t p = 0; p < in.directions.size(); ++p) {
        views.push_back(got.emplace_back(in.w, in.h, std::uint16_t{0x5A5A}).view);
      }
      for (std::size_t b = 0; b + 1 < edges.size(); ++b) {
        auto band = rowMemory<std::int32_t>(demux::kInterpolationRows, in.w);
        s.kernels->interpolation(in.frame.layout, in.tiles, in.columns, in.rows,
                                 demux::RowBlock<std::int32_t>(band, in.w), views,
                                 {edges[b], edges[b + 1]});
      }
      for (std::size_t p = 0; p < got.size(); ++p) {
        EXPECT_EQ(firstDifference(in.directions[p].view, got[p].view), "")
            << s.name << ", " << edges.size() - 1 << " band(s), projector " << p;
      }
    }
    // A band writes its own rows only: lanes write theirs at once.
    OwnedPlane<std::uint16_t> alone(in.w, in.h, std::uint16_t{0x5A5A});
    const std::vector<DirectionPlane> aloneViews(in.directions.size(), alone.view);
    auto band = rowMemory<std::int32_t>(demux::kInterpolationRows, in.w);
    s.kernels->interpolation(in.frame.layout, in.tiles, in.columns, in.rows,
                             demux::RowBlock<std::int32_t>(band, in.w), aloneViews, {3, in.h / 3});
    int outside = 0;
    for (int y = 0; y < in.h; ++y) {
      for (int x = 0; x < in.w; ++x) {
        outside += (y < 3 || y >= in.h / 3) && alone.view(x, y) != 0x5A5A ? 1 : 0;
      }
    }
    EXPECT_EQ(outside, 0) << s.name << ": pixels written outside the band";
  }
}

// Given the smoothed planes, tile directions and direction planes, every projector's separated
// planes and derivative orders are equal, whether the schedule sweeps the image in one band or
// in bands of uneven heights (the border rows alone among them), each band with working rows of
// its own as a lane has; a band alone writes its rows only; and some pixels are of each order
// the frame has.
void checkSeparation(const Frame& frame) {
  const Stages in(frame);
  const DemuxLayout& l = in.frame.layout;
  const std::vector<std::vector<int>> splits = {
      {0, in.h}, {0, 1, 3, in.h / 3, in.h - 2, in.h}, {3, in.h / 3}};
  for (const Schedule& s : schedules()) {
    for (const std::vector<int>& edges : splits) {
      const std::string bands = std::to_string(edges.size() - 1) + " band(s)";
      std::vector<OwnedPlanes3> separated;
      std::vector<OwnedPlane<std::uint8_t>> order;
      std::vector<demux::Planes3> separatedViews;
      std::vector<ImageView<std::uint8_t>> orderViews;
      separated.reserve(in.separated.size());
      order.reserve(in.order.size());
      for (std::size_t p = 0; p < in.separated.size(); ++p) {
        separatedViews.push_back(separated.emplace_back(in.w, in.h).views);
        orderViews.push_back(order.emplace_back(in.w, in.h, std::uint8_t{9}).view);
      }
      for (std::size_t b = 0; b + 1 < edges.size(); ++b) {
        auto filtered = rowMemory<std::int32_t>(demux::kFilterRows, in.w);
        auto work = rowMemory<std::int16_t>(demux::kWorkRows, in.w);
        s.kernels->separation(in.smoothed.views, l, in.tiles, in.columns, in.rows, in.units,
                              demux::RowBlock<std::int32_t>(filtered, in.w),
                              demux::RowBlock<std::int16_t>(work, in.w), in.directionViews(),
                              separatedViews, orderViews, {edges[b], edges[b + 1]});
      }
      const bool whole = edges.front() == 0 && edges.back() == in.h;
      for (std::size_t p = 0; p < separated.size() && whole; ++p) {
        for (std::size_t c = 0; c < 3; ++c) {
          EXPECT_EQ(firstDifference(in.separated[p].views[c], separated[p].views[c]), "")
              << s.name << ", " << bands << ", projector " << p << ", channel " << c;
        }
        EXPECT_EQ(firstDifference(in.order[p].view, order[p].view), "")
            << s.name << ", " << bands << ", projector " << p;
      }
      // A band alone writes its own rows only (lanes write theirs at once), as the whole sweep.
      for (std::size_t p = 0; p < separated.size() && !whole; ++p) {
        int wrong = 0;
        for (int y = 0; y < in.h; ++y) {
          const bool inside = y >= edges.front() && y < edges.back();
          for (int x = 0; x < in.w; ++x) {
            wrong += order[p].view(x, y) != (inside ? in.order[p].view(x, y) : 9) ? 1 : 0;
          }
        }
        EXPECT_EQ(wrong, 0) << s.name << ", rows " << edges.front() << " to " << edges.back()
                            << " alone, projector " << p;
      }
    }
  }
  int nonzero = 0;
  for (const auto& planes : in.separated) {
    for (int y = 0; y < in.h; ++y) {
      for (int x = 0; x < in.w; ++x) {
        nonzero += planes.views[0](x, y) != 0 ? 1 : 0;
      }
    }
  }
  EXPECT_GT(nonzero, in.w * in.h / 10);
}

// Given the separated planes, orders, direction planes and tile colours, every projector's
// strength planes and boundaries are equal, and there are many boundaries to compare.
void checkBoundaries(const Frame& frame) {
  const Stages in(frame);
  const DemuxLayout& l = in.frame.layout;
  const int minStrength = demux::minStrengthQ11(l.params);
  for (std::size_t p = 0; p < in.separated.size(); ++p) {
    OwnedPlane<std::uint16_t> relative(in.w, in.h, std::uint16_t{0x5A5A});
    OwnedPlane<std::uint16_t> derivative(in.w, in.h, std::uint16_t{0x5A5A});
    OwnedPlane<Boundary> expected(in.w, in.h, Boundary{1, 2, 3});
    ref::boundaries(in.separated[p].views, in.order[p].view, in.directions[p].view, in.units,
                    in.inverse, l, minStrength, {relative.view, derivative.view}, expected.view);
    int found = 0;
    for (int y = 0; y < in.h; ++y) {
      for (int x = 0; x < in.w; ++x) {
        found += expected.view(x, y).present() ? 1 : 0;
      }
    }
    EXPECT_GT(found, in.w * in.h / 25) << "projector " << p << ": too few boundaries to compare";
    for (const Schedule& s : schedules()) {
      OwnedPlane<std::uint16_t> gotRelative(in.w, in.h, std::uint16_t{0xA5A5});
      OwnedPlane<std::uint16_t> gotDerivative(in.w, in.h, std::uint16_t{0xA5A5});
      OwnedPlane<Boundary> got(in.w, in.h, Boundary{4, 5, 6});
      auto ring = rowMemory<std::int16_t>(demux::kBoundaryRingRows, in.w);
      const demux::TileColours colours{in.inverse, l.tilesX(), in.columns, in.rows};
      s.kernels->boundaries(in.separated[p].views, in.order[p].view, in.directions[p].view,
                            in.units, colours, minStrength,
                            demux::RowBlock<std::int16_t>(ring, in.w),
                            {gotRelative.view, gotDerivative.view}, got.view);
      const std::string which = s.name + ", projector " + std::to_string(p);
      EXPECT_EQ(firstDifference(relative.view, gotRelative.view), "") << which << ": strength";
      EXPECT_EQ(firstDifference(derivative.view, gotDerivative.view), "")
          << which << ": derivative strength";
      EXPECT_EQ(firstDifference(expected.view, got.view), "") << which << ": boundaries";
    }
  }
}

void forEachFrame(void (*check)(const Frame&)) {
  for (const Frame& f : frames()) {
    SCOPED_TRACE(f.name);
    check(f);
  }
}

TEST(DemuxReference, Smooth) {
  forEachFrame(checkSmooth);
}
TEST(DemuxReference, Histogram) {
  forEachFrame(checkHistogram);
}
TEST(DemuxReference, Directions) {
  forEachFrame(checkDirections);
}
TEST(DemuxReference, Interpolation) {
  forEachFrame(checkInterpolation);
}
TEST(DemuxReference, Separation) {
  forEachFrame(checkSeparation);
}
TEST(DemuxReference, Boundaries) {
  forEachFrame(checkBoundaries);
}

}  // namespace
}  // namespace smx::algo
