#include "smx/eval/wrong_depth.hpp"

#include <cmath>
#include <stdexcept>

#include "smx/eval/depth_eval.hpp"

namespace smx::eval {

const char* wrongKindName(WrongKind k) {
  switch (k) {
    case WrongKind::kLevel:
      return "level";
    case WrongKind::kPosition:
      return "position";
    case WrongKind::kUnlit:
      return "unlit";
  }
  return "?";
}

int WrongDepth::total() const {
  int n = 0;
  for (const auto& support : gross) {
    for (const int k : support) {
      n += k;
    }
  }
  return n;
}

WrongDepth classifyWrongDepth(std::span<const algo::ConstStripePlane> stripes,
                              std::span<const algo::ConstDepthPlane> depths,
                              std::span<const OwnedPlane<float>> truthStripes,
                              algo::ConstDepthPlane merged, algo::ImageView<const float> truthDepth,
                              const Mask& region, double depthUnitM) {
  const int w = merged.width();
  const int h = merged.height();
  if (stripes.size() != depths.size() || stripes.size() != truthStripes.size() ||
      region.width != w || region.height != h || truthDepth.width() != w ||
      truthDepth.height() != h) {
    throw std::invalid_argument("classifyWrongDepth: planes differ in number or size");
  }
  WrongDepth out;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double truth = truthDepth(x, y);
      if (region.at(x, y) == 0 || merged(x, y) == algo::kNoDepth || !std::isfinite(truth) ||
          !isGrossError(merged(x, y) * depthUnitM, truth)) {
        continue;
      }
      int withDepth = 0;
      int first = -1;
      for (std::size_t p = 0; p < depths.size(); ++p) {
        if (depths[p](x, y) != algo::kNoDepth) {
          first = withDepth == 0 ? static_cast<int>(p) : first;
          ++withDepth;
        }
      }
      if (first < 0) {
        continue;  // never: the merge gives depth only where a pair has some
      }
      const auto p = static_cast<std::size_t>(first);
      const double truthS = truthStripes[p].at(x, y);
      WrongKind kind = WrongKind::kUnlit;
      if (std::isfinite(truthS)) {
        const double s = static_cast<double>(stripes[p](x, y)) / algo::kStripeOne;
        kind =
            std::abs(s - truthS) >= kLevelErrorStripes ? WrongKind::kLevel : WrongKind::kPosition;
      }
      ++out.gross[withDepth > 1 ? 1 : 0][static_cast<std::size_t>(kind)];
    }
  }
  return out;
}

WrongDepth sumWrongDepth(std::span<const WrongDepth> runs) {
  WrongDepth sum;
  for (const auto& r : runs) {
    for (std::size_t a = 0; a < sum.gross.size(); ++a) {
      for (std::size_t k = 0; k < sum.gross[a].size(); ++k) {
        sum.gross[a][k] += r.gross[a][k];
      }
    }
  }
  return sum;
}

}  // namespace smx::eval
