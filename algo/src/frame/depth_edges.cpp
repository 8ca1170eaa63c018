// The depth-edge filter (depth_edges.hpp; not in the paper: it removes depths across jumps).
// filter<true> is the plain scalar definition; filter<false>, the schedule, looks at the eight
// neighbours of a pixel inside the image without bounds checks or a branch per value and gives
// the same output.
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

// The same for the inner pixels x = 1 … w − 2 of an inner row, without a branch per value:
// 1000 · |d| > limit is |d| > ⌊limit / 1000⌋ for integers, one unsigned comparison with z.
void filterInnerRow(const std::uint16_t* above, const std::uint16_t* at, const std::uint16_t* below,
                    std::uint16_t* out, int w, int maxJumpPermille) {
  for (int x = 1; x + 1 < w; ++x) {
    const std::int32_t z = at[x];
    const std::int32_t t = maxJumpPermille * z / 1000;
    const auto far = [z, t](std::uint16_t v) {
      return static_cast<std::uint32_t>(v != kNoDepth) &
             static_cast<std::uint32_t>(static_cast<std::uint32_t>(v - z + t) >
                                        static_cast<std::uint32_t>(2 * t));
    };
    const std::uint32_t edge = far(above[x - 1]) | far(above[x]) | far(above[x + 1]) |
                               far(at[x - 1]) | far(at[x + 1]) | far(below[x - 1]) | far(below[x]) |
                               far(below[x + 1]);
    out[x] = edge != 0 ? kNoDepth : static_cast<std::uint16_t>(z);
  }
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
    const auto pixel = [&](int x) {
      const std::int32_t z = row[x];
      const bool edge =
          z != kNoDepth && maxJumpPermille > 0 && edgeAt(in, x, y, z, maxJumpPermille * z);
      o[x] = edge ? kNoDepth : static_cast<std::uint16_t>(z);
    };
    if (!kReference && maxJumpPermille > 0 && y > 0 && y + 1 < h && w > 2) {
      filterInnerRow(in.rowPtr(y - 1), row, in.rowPtr(y + 1), o, w, maxJumpPermille);
      pixel(0);
      pixel(w - 1);
      continue;
    }
    for (int x = 0; x < w; ++x) {
      pixel(x);
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
