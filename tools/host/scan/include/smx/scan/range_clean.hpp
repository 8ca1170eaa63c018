#pragma once

#include "smx/algo/rig.hpp"
#include "smx/scan/range_view.hpp"

// What a fused model should not take from a range image: pixels next to a hole or a depth jump
// (a stripe decoded at a silhouette, mixed foreground and background) and pixels seeing the
// surface at grazing incidence, where a boundary error of a fraction of a pixel moves the depth
// most. Other views see those parts better; the TSDF averages what is left.
namespace smx::scan {

struct RangeCleanOptions {
  int edgePx = 2;                 // pixels within this of a hole or a jump are dropped; 0 keeps
  double jumpPerPx = 0.02;        // a jump: neighbours differing by more than this share of z
  double maxIncidenceDeg = 80.0;  // angle between the ray and the surface normal; 90 keeps
};

// Clears those pixels of every camera of `view`.
void cleanForFusion(RangeView& view, const algo::Rig& rig, const RangeCleanOptions& options = {});

}  // namespace smx::scan
