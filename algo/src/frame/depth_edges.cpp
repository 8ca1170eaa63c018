// The depth-edge filter (depth_edges.hpp; not in the paper: it removes depths across jumps).
// filter<true> is the plain scalar definition; filter<false>, the schedule, looks at the eight
// neighbours of a pixel inside the image without bounds checks and gives the same output.
#include "smx/algo/depth_edges.hpp"

#include <cstdint>

namespace smx::algo {

namespace {

// Whether a valid neighbour of (x, y) (or the pixel itself, which never is) lies farther from z
// than limit / 1000, the window clipped at the image border.
bool edgeAt(ConstDepthPlane in, int x, int y, std::int32_t z, std::int32_t limit) {
  const int w = in.width();
  const int h = in.height();
  for (int yy = y > 0 ? y - 1 : 0; yy <= (y + 1 < h ? y + 1 : y); ++yy) {
    const std::uint16_t* n = in.rowPtr(yy);
    for (int xx = x > 0 ? x - 1 : 0; xx <= (x + 1 < w ? x + 1 : x); ++xx) {
      const std::int32_t d = n[xx] - z;
      if (n[xx] != kNoDepth && 1000 * (d < 0 ? -d : d) > limit) {
        return true;
      }
    }
  }
  return false;
}

// The same for a pixel whose 3 × 3 window lies inside the image: rows above, at and below it,
// each pointing at the pixel's column.
bool edgeInside(const std::uint16_t* above, const std::uint16_t* at, const std::uint16_t* below,
                std::int32_t z, std::int32_t limit) {
  const auto far = [z, limit](std::uint16_t v) {
    const std::int32_t d = v - z;
    return v != kNoDepth && 1000 * (d < 0 ? -d : d) > limit;
  };
  return far(above[-1]) || far(above[0]) || far(above[1]) || far(at[-1]) || far(at[1]) ||
         far(below[-1]) || far(below[0]) || far(below[1]);
}

template <bool kReference>
Result<void> filter(ConstDepthPlane in, DepthPlane out, int maxJumpPermille) {
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
    const bool innerRow = !kReference && y > 0 && y + 1 < h;
    for (int x = 0; x < w; ++x) {
      const std::int32_t z = row[x];
      o[x] = static_cast<std::uint16_t>(z);
      if (z == kNoDepth || maxJumpPermille == 0) {
        continue;
      }
      const std::int32_t limit = maxJumpPermille * z;
      const bool edge = innerRow && x > 0 && x + 1 < w ? edgeInside(in.rowPtr(y - 1) + x, row + x,
                                                                    in.rowPtr(y + 1) + x, z, limit)
                                                       : edgeAt(in, x, y, z, limit);
      o[x] = edge ? kNoDepth : static_cast<std::uint16_t>(z);
    }
  }
  return {};
}

}  // namespace

Result<void> removeDepthEdges(ConstDepthPlane in, DepthPlane out, int maxJumpPermille) {
  return filter<false>(in, out, maxJumpPermille);
}

Result<void> removeDepthEdgesReference(ConstDepthPlane in, DepthPlane out, int maxJumpPermille) {
  return filter<true>(in, out, maxJumpPermille);
}

}  // namespace smx::algo
