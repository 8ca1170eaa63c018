#pragma once

#include "smx/algo/rig.hpp"
#include "smx/scan/range_view.hpp"

// A turntable scan's volume: only what stands on the table turns with it, so the room around
// (walls, the table's stand) would smear round the model once placed by the table's angle.
namespace smx::scan {

// Clears the depth of every pixel whose point lies farther than radiusM from the axis.
void keepOnTable(RangeView& view, const algo::Rig& rig, const TurntableAxis& axis, double radiusM);

}  // namespace smx::scan
