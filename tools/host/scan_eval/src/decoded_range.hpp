#pragma once

#include "smx/eval/sim_frame.hpp"
#include "smx/scan/range_view.hpp"

// A rendered frame through the firmware's pipeline, as the scan receives it from a device.
namespace smx::scan_eval::detail {

// Camera `camera`'s merged range image of `frame`, row by row.
[[nodiscard]] scan::CameraRange decoded(const eval::SimFrame& frame, int camera);

}  // namespace smx::scan_eval::detail
