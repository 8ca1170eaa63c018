// Stage 1 and the colour averages of stage 4: the schedule of smoothChannels() (reference:
// reference/smooth.cpp) and the tile colour sums and inverses, which are plain loops already.
//   Input   8-bit RGB.
//   Output  int16 planes, 16 × smoothed grey (0…4080): the 3×3 binomial kernel sums to 16; a
//           second pass (5×5 binomial overall, σ = 1 px) is rounded back by >> 4.
//   Accumulators int32 (tile sums uint32: a 64×64 tile of 4080 is < 2^24). Nothing saturates.
#include <cstddef>
#include <cstdint>

#include "demux_kernels.hpp"

namespace smx::algo::demux {

namespace {

template <int Channel>
void copyChannel(ConstRgbView image, ImageView<std::int16_t> out) {
  for (int y = 0; y < image.height(); ++y) {
    const std::uint8_t* src = &image.rowPtr(y)->r + Channel;
    std::int16_t* dst = out.rowPtr(y);
    for (int x = 0; x < image.width(); ++x) {
      dst[x] = static_cast<std::int16_t>(kSmoothScale * src[3 * static_cast<std::ptrdiff_t>(x)]);
    }
  }
}

// The first [1 2 1]ᵀ[1 2 1] pass straight from the RGB rows (edges repeated): 0…255 to
// 16 × grey, exact, so no rounding. The vertical sum runs over the interleaved row (contiguous,
// so it vectorises); the horizontal one splits the channels. vertical holds 3 × width values.
void firstPass(ConstRgbView image, const Planes3& out, std::int16_t* __restrict vertical) {
  const int w = image.width();
  const int h = image.height();
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* above = &image.rowPtr(y > 0 ? y - 1 : 0)->r;
    const std::uint8_t* centre = &image.rowPtr(y)->r;
    const std::uint8_t* below = &image.rowPtr(y + 1 < h ? y + 1 : h - 1)->r;
    for (int i = 0; i < 3 * w; ++i) {
      vertical[i] = static_cast<std::int16_t>(above[i] + 2 * centre[i] + below[i]);
    }
    std::int16_t* __restrict r = out[0].rowPtr(y);
    std::int16_t* __restrict g = out[1].rowPtr(y);
    std::int16_t* __restrict b = out[2].rowPtr(y);
    for (int x = 1; x + 1 < w; ++x) {
      const std::int16_t* v = vertical + 3 * static_cast<std::ptrdiff_t>(x);
      r[x] = static_cast<std::int16_t>(v[-3] + 2 * v[0] + v[3]);
      g[x] = static_cast<std::int16_t>(v[-2] + 2 * v[1] + v[4]);
      b[x] = static_cast<std::int16_t>(v[-1] + 2 * v[2] + v[5]);
    }
    for (std::size_t c = 0; c < 3; ++c) {
      const std::int16_t* v = vertical + c;
      std::int16_t* dst = out[c].rowPtr(y);
      const int right = 3 * (w - 1);
      dst[0] = static_cast<std::int16_t>(3 * v[0] + v[w > 1 ? 3 : 0]);
      dst[w - 1] = static_cast<std::int16_t>(v[w > 1 ? right - 3 : 0] + 3 * v[right]);
    }
  }
}

// One [1 2 1]ᵀ[1 2 1] pass in place, edges repeated, result (sum + half) >> shift.
// scratch holds 2 × width values.
void binomialPass(ImageView<std::int16_t> plane, int shift, std::int16_t* prev, std::int16_t* cur) {
  const int w = plane.width();
  const int h = plane.height();
  const std::int32_t half = shift > 0 ? 1 << (shift - 1) : 0;
  for (int y = 0; y < h; ++y) {
    std::int16_t* row = plane.rowPtr(y);
    for (int x = 0; x < w; ++x) {
      cur[x] = row[x];
    }
    for (int x = 0; x < w; ++x) {
      const std::int32_t left = cur[x > 0 ? x - 1 : 0];
      const std::int32_t right = cur[x + 1 < w ? x + 1 : w - 1];
      row[x] = static_cast<std::int16_t>(left + 2 * cur[x] + right);
    }
  }
  // Vertical: row y needs the horizontal rows y−1 (kept in prev), y and y+1.
  const std::int16_t* first = plane.rowPtr(0);
  for (int x = 0; x < w; ++x) {
    prev[x] = first[x];
  }
  for (int y = 0; y < h; ++y) {
    std::int16_t* row = plane.rowPtr(y);
    const std::int16_t* next = y + 1 < h ? plane.rowPtr(y + 1) : row;
    for (int x = 0; x < w; ++x) {
      cur[x] = row[x];
    }
    for (int x = 0; x < w; ++x) {
      row[x] = static_cast<std::int16_t>((prev[x] + 2 * cur[x] + next[x] + half) >> shift);
    }
    std::int16_t* t = prev;
    prev = cur;
    cur = t;
  }
}

}  // namespace

void smoothChannels(ConstRgbView image, const Planes3& out, int passes,
                    std::span<std::int16_t> rowScratch) {
  if (passes == 0) {
    copyChannel<0>(image, out[0]);
    copyChannel<1>(image, out[1]);
    copyChannel<2>(image, out[2]);
    return;
  }
  firstPass(image, out, rowScratch.data());
  const auto w = static_cast<std::size_t>(image.width());
  for (const auto& plane : out) {
    for (int pass = 1; pass < passes; ++pass) {
      // Later passes keep the scale of 16 × grey.
      binomialPass(plane, 4, rowScratch.data(), rowScratch.data() + w);
    }
  }
}

#if SMX_DEMUX_AVX2
SMX_AVX2_TWIN void avx2::smoothChannels(ConstRgbView image, const Planes3& out, int passes,
                                        std::span<std::int16_t> rowScratch) {
  demux::smoothChannels(image, out, passes, rowScratch);
}
#endif

namespace {

// Σ of the plane over each tile of one tile row, into tileRow[tx * 3]: per column over the rows
// first (lane-wise adds, where TilePx > 0 fixes the width at compile time and they vectorise), one
// reduction per tile.
template <int TilePx>
void sumTileRow(ImageView<const std::int16_t> plane, int y0, int y1, int tilePx,
                std::uint32_t* tileRow) {
  const int w = plane.width();
  const int t = TilePx > 0 ? TilePx : tilePx;
  for (int x0 = 0, tx = 0; x0 < w; x0 += t, ++tx) {
    const int n = x0 + t <= w ? t : w - x0;
    std::uint32_t acc = 0;
    if (TilePx > 0 && n == TilePx) {
      std::uint32_t lanes[TilePx > 0 ? std::size_t{TilePx} : 1] = {};
      for (int y = y0; y < y1; ++y) {
        const std::int16_t* row = plane.rowPtr(y) + x0;
        for (int x = 0; x < TilePx; ++x) {
          lanes[static_cast<std::size_t>(x)] += static_cast<std::uint32_t>(row[x]);
        }
      }
      for (const std::uint32_t lane : lanes) {
        acc += lane;
      }
    } else {
      for (int y = y0; y < y1; ++y) {
        const std::int16_t* row = plane.rowPtr(y) + x0;
        for (int x = 0; x < n; ++x) {
          acc += static_cast<std::uint32_t>(row[x]);
        }
      }
    }
    tileRow[static_cast<std::size_t>(tx) * 3] = acc;
  }
}

}  // namespace

void sumTileColours(const Planes3& smoothed, int tilePx, std::span<std::uint32_t> sums) {
  const int w = smoothed[0].width();
  const int h = smoothed[0].height();
  const auto tilesX = static_cast<std::size_t>((w + tilePx - 1) / tilePx);
  for (std::size_t c = 0; c < 3; ++c) {
    for (int y0 = 0, ty = 0; y0 < h; y0 += tilePx, ++ty) {
      const int y1 = y0 + tilePx < h ? y0 + tilePx : h;
      std::uint32_t* tileRow = sums.data() + static_cast<std::size_t>(ty) * tilesX * 3 + c;
      if (tilePx == 8) {
        sumTileRow<8>(smoothed[c], y0, y1, tilePx, tileRow);
      } else {
        sumTileRow<0>(smoothed[c], y0, y1, tilePx, tileRow);
      }
    }
  }
}

void inverseTileColours(std::span<const std::uint32_t> sums, const DemuxLayout& layout,
                        bool normalise, std::span<std::uint32_t> inverse) {
  const int tilesX = layout.tilesX();
  const int tilesY = layout.tilesY();
  const int r = layout.params.windowTiles / 2;
  const int t = layout.params.tilePx;
  for (int ty = 0; ty < tilesY; ++ty) {
    for (int tx = 0; tx < tilesX; ++tx) {
      const auto out = (static_cast<std::size_t>(ty) * static_cast<std::size_t>(tilesX) +
                        static_cast<std::size_t>(tx)) *
                       3;
      if (!normalise) {
        // A fixed mid-grey average: values stay proportional to the raw derivative.
        for (std::size_t c = 0; c < 3; ++c) {
          inverse[out + c] = (1U << kInverseShift) / (128U * kSmoothScale);
        }
        continue;
      }
      // 32 bits hold a window's sums (81 tiles of 64 × 64 × 4080 < 2^31), and its division is
      // cheaper.
      std::uint32_t acc[3] = {0, 0, 0};
      std::uint32_t pixels = 0;
      const int i0 = tx - r > 0 ? tx - r : 0;
      const int i1 = tx + r < tilesX ? tx + r : tilesX - 1;
      const int j0 = ty - r > 0 ? ty - r : 0;
      const int j1 = ty + r < tilesY ? ty + r : tilesY - 1;
      for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) {
          const auto in = (static_cast<std::size_t>(j) * static_cast<std::size_t>(tilesX) +
                           static_cast<std::size_t>(i)) *
                          3;
          for (std::size_t c = 0; c < 3; ++c) {
            acc[c] += sums[in + c];
          }
          const int tw = (i + 1) * t <= layout.width ? t : layout.width - i * t;
          const int th = (j + 1) * t <= layout.height ? t : layout.height - j * t;
          pixels += static_cast<std::uint32_t>(tw * th);
        }
      }
      for (std::size_t c = 0; c < 3; ++c) {
        std::uint32_t average = pixels > 0 ? acc[c] / pixels : 0;
        if (average < kColourFloor) {
          average = kColourFloor;
        }
        inverse[out + c] = (1U << kInverseShift) / average;
      }
    }
  }
}

}  // namespace smx::algo::demux
