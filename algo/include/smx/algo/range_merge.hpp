#pragma once

#include <cstdint>
#include <span>

#include "smx/algo/depth_trust.hpp"
#include "smx/algo/error.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/range_image.hpp"

// Merging one camera's range images, one per projector, into one (paper §4.3, "Occlusion";
// DESIGN.md item 9; docs/decode.md). The paper's variant of the median filter:
//
//   For each pixel, the valid values (≠ 0) of each range image in the 3×3 window (clipped at the
//   image border) form a set. Between two sets: if their member counts differ by more than 3,
//   the set with more members; otherwise the one with the smaller variance, and when the
//   variances are equal, both together. A one-member set has the largest variance; an empty set
//   is never chosen. The output is the median of the chosen set.
//
// Consistency first (not in the paper: the filter would average a wrong range into a right one).
// At each pixel the ranges with a value there vote: a value's support is the number of ranges
// whose value lies within the gross tolerance tol(z) of it (itself included); the first value
// with the most support is the reference when that support is a strict majority, otherwise the
// pixel gets no depth (two ranges that disagree: no depth; three: the two that agree outvote the
// third). A range whose value at the pixel disagrees with the reference takes no part; of the
// others only window values within tol of the reference form the sets below, so nothing that
// disagrees is ever blended in.
//
// Decisions where the paper is silent:
//   - Three or more sets: a left fold in projector order, the running choice (a set or a union)
//     against the next non-empty set. With two sets it is the paper's rule exactly.
//   - The median of an even count is the mean of the two middle values, rounded half up.
//   - A pixel gets a value only where at least one range image has one at the pixel itself, so
//     merging never grows a surface past a silhouette or into a shadow.
//
// Numerics: per set n ≤ 9·kMaxRanges values, Σz and Σz² in int64; variances compared exactly as
// (n_a·Σz_a² − (Σz_a)²)·n_b² against the same for b (|·| < 72·72·72·65535² < 2^61). Integer only,
// no heap.
namespace smx::algo {

inline constexpr int kMaxRanges = 8;

// Rows [begin, end) of the output (clipped to it). An output row reads only the input rows
// beside it, so the merge cut into bands of rows gives the same planes, band by band at once.
struct RowBand {
  int begin = 0;
  int end = 1 << 30;
};

// 1…kMaxRanges inputs, all the size of `out` (which may not alias them). A tolerance of
// {65535, 0} lets every value agree: the paper's filter alone.
[[nodiscard]] Result<void> mergeRanges(std::span<const ConstDepthPlane> ranges, DepthPlane out,
                                       const DepthTolerance& tolerance = {});

// The same, with each range's confidence (depth_trust.hpp) and the merged confidence: the
// smallest predicted error u = 255 − c among the ranges that agree with the reference at the
// pixel, divided by √k for k of them (independent measurements; 256/√k rounded, Q8), as
// 255 − u; 0 where the merged plane has no depth. Only `rows` of both outputs are written.
[[nodiscard]] Result<void> mergeRanges(std::span<const ConstDepthPlane> ranges,
                                       std::span<const ImageView<const std::uint8_t>> confidences,
                                       DepthPlane out, ImageView<std::uint8_t> outConfidence,
                                       const DepthTolerance& tolerance = {}, RowBand rows = {});

// The same as the plain scalar definition, which the schedule above must equal bit for bit
// (PipelineSchedule.* compares them); for the tests and the benchmarks.
[[nodiscard]] Result<void> mergeRangesReference(
    std::span<const ConstDepthPlane> ranges,
    std::span<const ImageView<const std::uint8_t>> confidences, DepthPlane out,
    ImageView<std::uint8_t> outConfidence, const DepthTolerance& tolerance = {});

}  // namespace smx::algo
