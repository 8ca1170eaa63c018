// The demultiplexer's two builds of its vectorised stages (demux_kernels.hpp): where the CPU
// runs AVX2, run() takes the AVX2 twins, and they give the baseline build's output bit for bit.
// Elsewhere (aarch64, or an x86-64 without AVX2) there is one build and the test skips.
#include "demux_kernels.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

#include "smx/algo/demux.hpp"
#include "smx/algo/fixed_math.hpp"
#include "synthetic_stripes.hpp"

namespace smx::algo {
namespace {

using test::SyntheticPattern;

// A demultiplexer over its own memory.
struct OwnedDemux {
  std::vector<std::byte> memory;
  Arena arena;
  Demultiplexer demux;

  OwnedDemux(const DemuxLayout& layout, const std::vector<std::uint16_t>& predicted,
             DemuxSchedule schedule)
      : memory(*Demultiplexer::workspaceBytes(layout)),
        arena(memory),
        demux(*Demultiplexer::create(layout, predicted, arena, schedule)) {}
};

template <class T>
bool sameRows(ImageView<const T> a, ImageView<const T> b) {
  for (int y = 0; y < a.height(); ++y) {
    if (std::memcmp(a.rowPtr(y), b.rowPtr(y), static_cast<std::size_t>(a.width()) * sizeof(T)) !=
        0) {
      return false;
    }
  }
  return true;
}

// The patterns superposed on a surface whose colour varies, with noise of σ 8 grey levels, so
// that the strength plateaus, contrast floors and colour divisors all take many values.
std::vector<Rgb8> noisyFrame(const std::vector<SyntheticPattern>& patterns, int w, int h) {
  std::vector<Rgb8> image = test::superpose(patterns, w, h);
  test::colourAndNoise(image, w, h, 7);
  return image;
}

// Given the CPU runs AVX2, when a frame of 2 and one of 3 superposed patterns run through both
// builds (a width that is no multiple of the vector lengths, so the loops' tails run), then every
// projector's boundaries, direction plane, separated planes and tile directions are equal.
class DemuxKernels : public ::testing::TestWithParam<std::vector<SyntheticPattern>> {};

TEST_P(DemuxKernels, TheAvx2BuildGivesTheBaselineOutput) {
  if (&demux::fastestKernels() == &demux::baselineKernels()) {
#if SMX_DEMUX_AVX2
    ASSERT_FALSE(__builtin_cpu_supports("avx2")) << "the CPU has AVX2 but run() would not use it";
#endif
    GTEST_SKIP() << "one build of the kernels here (no AVX2 twins, or a CPU without AVX2)";
  }
  const auto& patterns = GetParam();
  constexpr int kW = 211;
  constexpr int kH = 97;
  const DemuxLayout layout{kW, kH, static_cast<int>(patterns.size()), {}};
  std::vector<std::uint16_t> predicted;
  for (std::size_t t = 0; t < layout.tileCount(); ++t) {
    for (const auto& p : patterns) {
      predicted.push_back(BinAngle::fromDegrees(p.angleDeg + 4.0).raw);
    }
  }
  const auto image = noisyFrame(patterns, kW, kH);
  const auto view = *ConstRgbView::packed(image, kW, kH);
  OwnedDemux fast(layout, predicted, DemuxSchedule::kAutomatic);
  OwnedDemux baseline(layout, predicted, DemuxSchedule::kBaseline);
  ASSERT_TRUE(fast.demux.run(view).has_value());
  ASSERT_TRUE(baseline.demux.run(view).has_value());

  for (int p = 0; p < layout.projectors; ++p) {
    const std::string which = "projector " + std::to_string(p);
    int found = 0;
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        found += fast.demux.boundaries(p)(x, y).present() ? 1 : 0;
      }
    }
    EXPECT_GT(found, kW * kH / 20) << which << ": too few boundaries to compare";
    EXPECT_TRUE(sameRows(fast.demux.boundaries(p), baseline.demux.boundaries(p))) << which;
    EXPECT_TRUE(sameRows(fast.demux.directions(p), baseline.demux.directions(p))) << which;
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(sameRows(fast.demux.separated(p, c), baseline.demux.separated(p, c)))
          << which << ", channel " << c;
    }
    const auto a = fast.demux.tileDirections(p);
    const auto b = baseline.demux.tileDirections(p);
    for (std::size_t t = 0; t < a.size(); ++t) {
      EXPECT_EQ(a[t].angle, b[t].angle) << which << ", tile " << t;
      EXPECT_EQ(a[t].present, b[t].present) << which << ", tile " << t;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Patterns, DemuxKernels,
    ::testing::Values(std::vector<SyntheticPattern>{{0, 4.5}, {70, 4.5}},
                      std::vector<SyntheticPattern>{{0, 5.0}, {60, 5.0}, {120, 5.0}}),
    [](const auto& param) { return std::to_string(param.param.size()) + "Patterns"; });

}  // namespace
}  // namespace smx::algo
