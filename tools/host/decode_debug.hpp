#pragma once

#include <cstdint>

#include "smx/algo/image_view.hpp"
#include "smx/algo/range_image.hpp"
#include "smx/sim/png_io.hpp"

// Debug renderings of decoding and range output: what a person looks at to see whether the
// stripes were decoded and the surface came out right.
namespace smx::host {

// Depth colour-mapped from near (red) through yellow, green and cyan to far (blue) over
// [nearUnits, farUnits]; black where there is no data. nearUnits = farUnits = 0 picks the 1st
// and 99th percentiles of the valid depths.
[[nodiscard]] sim::RgbImage renderDepth(algo::ConstDepthPlane depth, std::uint16_t nearUnits = 0,
                                        std::uint16_t farUnits = 0);

// The decoded stripe coordinate: each stripe in a colour that changes from one stripe to the
// next (hue by index), darker towards its start; black where nothing was decoded. Stripes come
// out as smooth bands where decoding worked, and as a different hue where a level is wrong.
[[nodiscard]] sim::RgbImage renderStripes(algo::ConstStripePlane stripe);

}  // namespace smx::host
