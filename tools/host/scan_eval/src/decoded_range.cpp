#include "decoded_range.hpp"

#include "smx/eval/frame_eval.hpp"

namespace smx::scan_eval::detail {

scan::CameraRange decoded(const eval::SimFrame& frame, int camera) {
  const auto run = eval::runPipeline(frame, camera);
  const algo::ConstDepthPlane merged = run->pipeline->merged();
  scan::CameraRange range;
  range.width = merged.width();
  range.height = merged.height();
  range.depth.reserve(static_cast<std::size_t>(range.width) *
                      static_cast<std::size_t>(range.height));
  for (int y = 0; y < range.height; ++y) {
    const auto row = merged.row(y);
    range.depth.insert(range.depth.end(), row.begin(), row.end());
  }
  return range;
}

}  // namespace smx::scan_eval::detail
