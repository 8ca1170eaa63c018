// Triangulation per frame (triangulation.hpp; paper §4.2: range from the decoded stripe
// coordinate and the calibration): the tables copied into the arena at create(), one integer
// division per pixel. This scalar code is the reference; the pipeline runs it together with the
// trust filter as triangulateTrusted() (depth_trust_schedule.cpp).
#include <cstdint>

#include "smx/algo/triangulation.hpp"

namespace smx::algo {

namespace {

Result<std::size_t> bytesFor(int width, int height, bool perPixelNumerators) {
  if (width < 1 || height < 1 || width > 8192 || height > 8192) {
    return fail(Errc::kInvalidArgument, "triangulation: image size must be 1 to 8192 per side");
  }
  const auto pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  ArenaSizer sizer;
  (void)sizer.allocate<std::int32_t>(pixels);
  (void)sizer.allocate<std::int32_t>(pixels);
  (void)sizer.allocate<std::int8_t>(pixels);
  if (perPixelNumerators) {
    (void)sizer.allocate<PixelNumerator>(pixels);
  }
  return sizer.bytes();
}

}  // namespace

Result<std::size_t> Triangulator::workspaceBytes(int width, int height) {
  return bytesFor(width, height, false);
}

Result<std::size_t> Triangulator::workspaceBytes(const TriangulationTables& tables) {
  return bytesFor(tables.width, tables.height, !tables.numerators.empty());
}

Result<Triangulator> Triangulator::create(const TriangulationTables& tables, Arena& arena) {
  if (auto bytes = workspaceBytes(tables.width, tables.height); !bytes) {
    return std::unexpected(bytes.error());
  }
  const auto pixels =
      static_cast<std::size_t>(tables.width) * static_cast<std::size_t>(tables.height);
  const bool perPixel = !tables.numerators.empty();
  if (tables.denominatorBase.size() != pixels || tables.denominatorSlope.size() != pixels ||
      tables.sense.size() != pixels || (perPixel && tables.numerators.size() != pixels)) {
    return fail(Errc::kSizeMismatch, "triangulation: tables must hold width x height entries");
  }
  Triangulator t;
  t.width_ = tables.width;
  t.height_ = tables.height;
  t.numeratorBase_ = tables.numeratorBase;
  t.numeratorSlope_ = tables.numeratorSlope;
  const Arena::Marker start = arena.mark();
  Result<void> ok = carveSpan(arena, t.base_, pixels);
  ok = ok ? carveSpan(arena, t.slope_, pixels) : ok;
  ok = ok ? carveSpan(arena, t.sense_, pixels) : ok;
  if (perPixel) {
    ok = ok ? carveSpan(arena, t.numerators_, pixels) : ok;
  }
  if (!ok) {
    arena.rewind(start);
    return std::unexpected(ok.error());
  }
  for (std::size_t i = 0; i < pixels; ++i) {
    t.base_[i] = tables.denominatorBase[i];
    t.slope_[i] = tables.denominatorSlope[i];
    t.sense_[i] = tables.sense[i];
  }
  if (perPixel) {
    for (std::size_t i = 0; i < pixels; ++i) {
      t.numerators_[i] = tables.numerators[i];
    }
  }
  return t;
}

template <bool kPerPixel>
void Triangulator::runRows(ConstStripePlane stripe, DepthPlane depth) const {
  const Lookup l = lookup();
  for (int y = 0; y < height_; ++y) {
    const StripeQ16* s = stripe.rowPtr(y);
    std::uint16_t* z = depth.rowPtr(y);
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(width_);
    for (int x = 0; x < width_; ++x) {
      z[x] = l.depth<kPerPixel>(row + static_cast<std::size_t>(x), s[x]);
    }
  }
}

Result<void> Triangulator::run(ConstStripePlane stripe, DepthPlane depth) const {
  if (stripe.width() != width_ || stripe.height() != height_ || depth.width() != width_ ||
      depth.height() != height_) {
    return fail(Errc::kSizeMismatch,
                "triangulation: stripe and depth planes must match the tables");
  }
  if (numerators_.empty()) {
    runRows<false>(stripe, depth);
  } else {
    runRows<true>(stripe, depth);
  }
  return {};
}

}  // namespace smx::algo
