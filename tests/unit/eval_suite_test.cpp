// The evaluation suite's own measuring tools (stripemux eval, docs/results.md) on inputs whose
// answer is known by construction: the plane fit of a flat target, and the true tile directions
// of the true-directions baseline.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "smx/algo/fixed_math.hpp"
#include "smx/eval/frame_eval.hpp"
#include "smx/eval/suite.hpp"

namespace smx::eval {
namespace {

algo::Camera pinhole(int w, int h) {
  algo::Camera c;
  c.width = w;
  c.height = h;
  c.K = {500.0, 0, (w - 1) / 2.0, 0, 500.0, (h - 1) / 2.0, 0, 0, 1};
  c.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  return c;
}

// Depth units of the tilted plane z = 0.8 m + 0.3·X (X = x_n·z) at pixel column x.
std::uint16_t tiltedPlaneUnits(const algo::Camera& c, int x) {
  const double xn = (x - c.cx()) / c.fx();
  const double z = 0.8 / (1.0 - 0.3 * xn);
  return static_cast<std::uint16_t>(std::lround(z / algo::kDefaultDepthUnitM));
}

// Given a tilted plane whose depth alternates by ±2 units (0.2 mm along z) in a checkerboard,
// with a quarter of the region left without depth, when the plane is fitted, then the fill
// rate is 3/4 and the RMS distance to the plane is the alternation's 0.2 mm times the cosine of
// the tilt (less the 0.1 mm rounding grid's share, within 0.03 mm).
TEST(EvalPlaneFit, NoiseAndFillRateOfATiltedPlane) {
  constexpr int kW = 80;
  constexpr int kH = 60;
  const auto cam = pinhole(kW, kH);
  OwnedPlane<std::uint16_t> depth(kW, kH, 0);
  const Mask region = Mask::filled(kW, kH, 255);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      if (x < kW / 4) {
        continue;  // no depth here
      }
      const int sign = (x + y) % 2 == 0 ? 1 : -1;
      depth.pixels[(static_cast<std::size_t>(y) * kW) + static_cast<std::size_t>(x)] =
          static_cast<std::uint16_t>(tiltedPlaneUnits(cam, x) + 2 * sign);
    }
  }
  const PlaneFit fit = fitPlane(cam, depth.view(), region.view());
  EXPECT_EQ(fit.regionPixels, kW * kH);
  EXPECT_NEAR(fit.fillRate, 0.75, 1e-9);
  const double cosTilt = 1.0 / std::sqrt(1.0 + 0.3 * 0.3);
  EXPECT_NEAR(fit.rmsMm, 0.2 * cosTilt, 0.03);
}

TEST(EvalPlaneFit, AnExactPlaneHasOnlyTheRoundingOfItsDepthUnits) {
  const auto cam = pinhole(64, 48);
  OwnedPlane<std::uint16_t> depth(64, 48, 0);
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      depth.pixels[(static_cast<std::size_t>(y) * 64) + static_cast<std::size_t>(x)] =
          tiltedPlaneUnits(cam, x);
    }
  }
  const Mask region = Mask::filled(64, 48, 255);
  const PlaneFit fit = fitPlane(cam, depth.view(), region.view());
  EXPECT_NEAR(fit.fillRate, 1.0, 1e-12);
  EXPECT_LT(fit.rmsMm, 0.05);  // rounding to 0.1 mm units: ≈ 0.029 mm
}

// A frame whose projector 0 has stripes growing along +x and projector 1 along −y (up), with
// projector 1 absent (NaN) in the left half.
SimFrame stripedFrame(int w, int h) {
  SimFrame f;
  f.image = OwnedPlane<algo::Rgb8>(w, h, algo::Rgb8{});
  f.depth = OwnedPlane<float>(w, h, 1.0F);
  f.stripe.emplace_back(w, h, 0.0F);
  f.stripe.emplace_back(w, h, 0.0F);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const auto i =
          (static_cast<std::size_t>(y) * static_cast<std::size_t>(w)) + static_cast<std::size_t>(x);
      f.stripe[0].pixels[i] = 20.0F + static_cast<float>(x) / 6.0F;
      f.stripe[1].pixels[i] = x < w / 2 ? nan : 100.0F - static_cast<float>(y) / 5.0F;
    }
  }
  return f;
}

// Given stripes growing along +x (projector 0) and along −y (projector 1, right half only), when
// the true tile directions are taken, then projector 0's tiles point at 0°, projector 1's at
// −90° where it lights the tile, and its unlit tiles keep the fallback's angle and are absent.
TEST(EvalTrueDirections, TilesPointWhereTheStripesGrow) {
  constexpr int kW = 64;
  constexpr int kH = 32;
  const SimFrame f = stripedFrame(kW, kH);
  const algo::DemuxLayout layout{kW, kH, 2, {}};
  const std::uint16_t fallbackAngle = algo::BinAngle::fromDegrees(33.0).raw;
  const std::vector<algo::TileDirection> fallback(layout.tileCount() * 2,
                                                  algo::TileDirection{fallbackAngle, 1});
  const auto tiles = trueTileDirections(f, layout, fallback);
  ASSERT_EQ(tiles.size(), fallback.size());
  const std::uint16_t up = algo::BinAngle::fromDegrees(-90.0).raw;
  for (int ty = 0; ty < layout.tilesY(); ++ty) {
    for (int tx = 0; tx < layout.tilesX(); ++tx) {
      const auto t = (static_cast<std::size_t>(ty) * static_cast<std::size_t>(layout.tilesX())) +
                     static_cast<std::size_t>(tx);
      EXPECT_EQ(tiles[t].present, 1);
      EXPECT_EQ(tiles[t].angle, 0) << "tile " << tx << "," << ty;
      const auto& p1 = tiles[layout.tileCount() + t];
      if (tx * layout.params.tilePx >= kW / 2) {
        EXPECT_EQ(p1.present, 1);
        EXPECT_EQ(p1.angle, up) << "tile " << tx << "," << ty;
      } else {
        EXPECT_EQ(p1.present, 0);
        EXPECT_EQ(p1.angle, fallbackAngle);
      }
    }
  }
  EXPECT_THROW((void)trueTileDirections(f, layout, std::span(fallback).first(3)),
               std::invalid_argument);
}

}  // namespace
}  // namespace smx::eval
