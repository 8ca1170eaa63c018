#pragma once

#include <cstdint>
#include <expected>
#include <string>
#include <vector>

#include "smx/algo/demux.hpp"
#include "smx/algo/rig.hpp"

// Init time (double): where each projector's stripe-encoding axis points in a camera's image,
// from calibration. The doubled-angle histogram only knows orientations; the prediction gives
// each lobe its projector and its sign (DESIGN.md trap 3).
namespace smx::algo {

// For each tile of the layout and each projector: the direction (BinAngle raw) in which the
// projector's stripe coordinate grows fastest at the tile centre, for a surface facing the
// camera at nominalDepthM (z in the camera frame). Tile-major: [tile * projectors + p], as
// Demultiplexer::create takes it. Where the nominal surface point is not in front of the
// projector, the direction at the image centre is used.
[[nodiscard]] std::expected<std::vector<std::uint16_t>, std::string> predictEncodingAngles(
    const Rig& rig, int camera, const DemuxLayout& layout, double nominalDepthM);

}  // namespace smx::algo
