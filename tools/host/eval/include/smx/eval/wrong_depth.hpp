#pragma once

#include <array>
#include <span>

#include "smx/algo/range_image.hpp"
#include "smx/eval/boundary_eval.hpp"
#include "smx/eval/sim_frame.hpp"

// What the merged image's wrong depths are (docs/results.md, "What the wrong depths are"): each
// gross pixel of a region, judged against the truth stripe coordinate of a projector whose own
// range image has depth there. Where it came from:
//   alone         one projector has depth at the pixel (nothing to outvote it);
//   corroborated  two or more do;
// and what went wrong with that projector's decoded stripe coordinate s (the first projector with
// depth at the pixel):
//   unlit     the projector does not light the pixel (no truth coordinate there);
//   level     |s − s_truth| ≥ kLevelErrorStripes: a wrong stripe level;
//   position  under it: the right level, the boundaries misplaced.
// Host code, double precision; gross as depth_eval.hpp defines it.
namespace smx::eval {

inline constexpr double kLevelErrorStripes = 0.5;

enum class WrongKind : int { kLevel, kPosition, kUnlit };
inline constexpr int kWrongKinds = 3;

[[nodiscard]] const char* wrongKindName(WrongKind k);  // "level", "position", "unlit"

struct WrongDepth {
  // [alone (0) or corroborated (1)][WrongKind]
  std::array<std::array<int, kWrongKinds>, 2> gross{};
  [[nodiscard]] int total() const;
};

// The merged image against the truth in `region`; `stripes` and `depths` per projector (decoded
// coordinates and each pair's range image), `truthStripes` per projector (NaN where unlit).
[[nodiscard]] WrongDepth classifyWrongDepth(std::span<const algo::ConstStripePlane> stripes,
                                            std::span<const algo::ConstDepthPlane> depths,
                                            std::span<const OwnedPlane<float>> truthStripes,
                                            algo::ConstDepthPlane merged,
                                            algo::ImageView<const float> truthDepth,
                                            const Mask& region, double depthUnitM);
[[nodiscard]] WrongDepth sumWrongDepth(std::span<const WrongDepth> runs);

}  // namespace smx::eval
