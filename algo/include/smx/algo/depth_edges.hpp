#pragma once

#include "smx/algo/error.hpp"
#include "smx/algo/range_image.hpp"

// Depth-edge filter (not in the paper; what depth cameras call removing "flying pixels"): a pixel
// whose depth differs from a valid 8-neighbour's by more than maxJumpPermille ‰ of its own is
// dropped. At an occlusion contour the camera pixel sees both surfaces and its stripe coordinate
// is a mix, so its depth belongs to neither; the filter removes one pixel on each side of every
// depth jump and leaves smooth surfaces alone.
//
// Numerics: |z − z_n| · 1000 > maxJumpPermille · z in int32 (z < 2^16, ‰ ≤ 1000). Integer only,
// no heap.
namespace smx::algo {

// in → out (same size, must not alias); maxJumpPermille 0 copies unchanged.
[[nodiscard]] Result<void> removeDepthEdges(ConstDepthPlane in, DepthPlane out,
                                            int maxJumpPermille);

// The same as its plain scalar definition, which the schedule above must equal bit for bit
// (PipelineSchedule.* compares them); for the tests and the benchmarks.
[[nodiscard]] Result<void> removeDepthEdgesReference(ConstDepthPlane in, DepthPlane out,
                                                     int maxJumpPermille);

}  // namespace smx::algo
