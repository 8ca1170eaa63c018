// The depth-edge filter (depth_edges.hpp; not in the paper: it removes depths across jumps).
// This scalar code is the reference; no separate schedule exists.
#include "smx/algo/depth_edges.hpp"

#include <cstdint>

namespace smx::algo {

Result<void> removeDepthEdges(ConstDepthPlane in, DepthPlane out, int maxJumpPermille) {
  if (in.width() != out.width() || in.height() != out.height()) {
    return fail(Errc::kSizeMismatch, "depth edges: planes must have the same size");
  }
  if (maxJumpPermille < 0 || maxJumpPermille > 1000) {
    return fail(Errc::kInvalidArgument, "depth edges: the jump is 0 to 1000 per mille");
  }
  const int w = in.width();
  const int h = in.height();
  for (int y = 0; y < h; ++y) {
    const std::uint16_t* row = in.rowPtr(y);
    std::uint16_t* o = out.rowPtr(y);
    for (int x = 0; x < w; ++x) {
      const std::int32_t z = row[x];
      o[x] = static_cast<std::uint16_t>(z);
      if (z == kNoDepth || maxJumpPermille == 0) {
        continue;
      }
      const std::int32_t limit = maxJumpPermille * z;
      bool edge = false;
      for (int yy = y > 0 ? y - 1 : 0; yy <= (y + 1 < h ? y + 1 : y) && !edge; ++yy) {
        const std::uint16_t* n = in.rowPtr(yy);
        for (int xx = x > 0 ? x - 1 : 0; xx <= (x + 1 < w ? x + 1 : x); ++xx) {
          const std::int32_t d = n[xx] - z;
          if (n[xx] != kNoDepth && 1000 * (d < 0 ? -d : d) > limit) {
            edge = true;
            break;
          }
        }
      }
      o[x] = edge ? kNoDepth : static_cast<std::uint16_t>(z);
    }
  }
  return {};
}

}  // namespace smx::algo
