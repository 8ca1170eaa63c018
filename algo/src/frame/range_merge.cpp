// The median-variant merge (range_merge.hpp; paper §4.2, "data merging stage": the ranges of
// the separated patterns merged per image). merge<true> is the plain scalar definition,
// merge<false> the schedule: the same sets and median, reached with fewer steps (pixels without
// depth passed over, each row's 3 × 1 columns sorted and summed once for the three windows that
// hold them, agreeing full windows taken whole from their columns, sets gathered in place, the
// median by selection instead of sorting).
#include "smx/algo/range_merge.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

namespace smx::algo {

namespace {

constexpr int kWindow = 9;
constexpr int kMaxValues = kWindow * kMaxRanges;

// A candidate set's member count and sums (its members are kept by mergeRanges).
struct Set {
  int count = 0;
  std::int64_t sum = 0;
  std::int64_t sumSquares = 0;
};

// −1: a has the smaller variance, 1: b, 0: equal. One-member sets have the largest variance.
int compareVariance(const Set& a, const Set& b) {
  if (a.count == 1 || b.count == 1) {
    return a.count == b.count ? 0 : (a.count == 1 ? 1 : -1);
  }
  const std::int64_t na = a.count;
  const std::int64_t nb = b.count;
  const std::int64_t va = (na * a.sumSquares - a.sum * a.sum) * nb * nb;
  const std::int64_t vb = (nb * b.sumSquares - b.sum * b.sum) * na * na;
  return va < vb ? -1 : (vb < va ? 1 : 0);
}

// Median of v[0 … n), n ≥ 1, sorting it in place (insertion sort: n ≤ 72, usually ≤ 18).
std::uint16_t medianBySorting(std::array<std::uint16_t, kMaxValues>& v, std::size_t n) {
  for (std::size_t i = 1; i < n; ++i) {
    const std::uint16_t x = v[i];
    std::size_t j = i;
    while (j > 0 && v[j - 1] > x) {
      v[j] = v[j - 1];
      --j;
    }
    v[j] = x;
  }
  const std::size_t mid = n / 2;
  if (n % 2 == 1) {
    return v[mid];
  }
  return static_cast<std::uint16_t>((std::uint32_t{v[mid - 1]} + v[mid] + 1) / 2);
}

// The same median by selection: the middle value in place, and for an even count the largest
// value below it, as sorting would leave them.
std::uint16_t medianBySelection(std::array<std::uint16_t, kMaxValues>& v, std::size_t n) {
  const std::size_t mid = n / 2;
  std::uint16_t* const first = v.data();
  std::uint16_t* const middle = first + mid;
  std::nth_element(first, middle, first + n);
  if (n % 2 == 1) {
    return *middle;
  }
  const std::uint16_t below = *std::max_element(first, middle);
  return static_cast<std::uint16_t>((std::uint32_t{below} + *middle + 1) / 2);
}

// The schedule's 3 × 1 column of one range at one column of the row: its values sorted, their sum
// and sum of squares. A 3 × 3 window is three columns side by side, and its extremes, sums and
// median follow from theirs, each column computed once for the three windows that hold it.
struct Column {
  std::uint16_t lo;
  std::uint16_t mid;
  std::uint16_t hi;
  std::int32_t sum;
  std::int64_t squares;
};

// The columns of one chunk of a row: column cx − 1 + k at index k.
constexpr int kChunk = 64;
using ChunkColumns = std::array<Column, kChunk + 2>;

// Columns first … last (inside the image) of range r around inner row y, for the chunk at cx.
void fillColumns(const ConstDepthPlane& r, int y, int cx, int first, int last,
                 ChunkColumns& columns) {
  const std::uint16_t* above = r.rowPtr(y - 1);
  const std::uint16_t* at = r.rowPtr(y);
  const std::uint16_t* below = r.rowPtr(y + 1);
  for (int c = first; c <= last; ++c) {
    const std::int32_t a = above[c];
    const std::int32_t b = at[c];
    const std::int32_t d = below[c];
    const std::int32_t lo = std::min(std::min(a, b), d);
    const std::int32_t hi = std::max(std::max(a, b), d);
    const std::int32_t sum = a + b + d;
    const int k = c - cx + 1;
    columns[static_cast<std::size_t>(k)] = {
        static_cast<std::uint16_t>(lo), static_cast<std::uint16_t>(sum - lo - hi),
        static_cast<std::uint16_t>(hi), sum,
        std::int64_t{a} * a + std::int64_t{b} * b + std::int64_t{d} * d};
  }
}

std::int32_t medianOfThree(std::int32_t a, std::int32_t b, std::int32_t c) {
  return std::max(std::min(a, b), std::min(std::max(a, b), c));
}

// The median of the window whose columns are c[0], c[1], c[2]: of nine values, it is the median
// of the largest column minimum, the median column median and the smallest column maximum.
std::uint16_t medianOfColumns(const Column* c) {
  const std::int32_t lows = std::max(std::max(c[0].lo, c[1].lo), c[2].lo);
  const std::int32_t mids = medianOfThree(c[0].mid, c[1].mid, c[2].mid);
  const std::int32_t highs = std::min(std::min(c[0].hi, c[1].hi), c[2].hi);
  return static_cast<std::uint16_t>(medianOfThree(lows, mids, highs));
}

// The window whose columns are c[0 … 3) as a set when all nine values lie in [low, low + span]
// (so none is kNoDepth); false otherwise.
bool fullWindow(const Column* c, std::int32_t low, std::uint32_t span, Set& set) {
  const std::int32_t lo = std::min(std::min(c[0].lo, c[1].lo), c[2].lo);
  const std::int32_t hi = std::max(std::max(c[0].hi, c[1].hi), c[2].hi);
  if (lo < low || static_cast<std::uint32_t>(hi - low) > span) {
    return false;
  }
  set = {kWindow, std::int64_t{c[0].sum} + c[1].sum + c[2].sum,
         c[0].squares + c[1].squares + c[2].squares};
  return true;
}

// The nine values of range r's window at inner pixel (x, y) into v.
void gatherWindow(const ConstDepthPlane& r, int x, int y, std::uint16_t* v) {
  for (int dy = -1; dy <= 1; ++dy) {
    const std::uint16_t* row = r.rowPtr(y + dy) + x;
    for (int dx = -1; dx <= 1; ++dx) {
      *v++ = row[dx];
    }
  }
}

// 256 / √k, rounded: the predicted error of the mean of k agreeing ranges (Q8), k = 0…8.
constexpr std::array<std::int32_t, kMaxRanges + 1> kInverseSqrtQ8 = {256, 256, 181, 148, 128,
                                                                     114, 105, 97,  91};

// The reference value at a pixel from the ranges' centre values (0: none), or 0 when no value
// has a strict majority within the tolerance.
std::uint16_t reference(const std::array<std::uint16_t, kMaxRanges>& centre, std::size_t n,
                        const DepthTolerance& tolerance) {
  int present = 0;
  std::uint16_t first = kNoDepth;
  for (std::size_t i = 0; i < n; ++i) {
    present += centre[i] != kNoDepth ? 1 : 0;
    first = first == kNoDepth ? centre[i] : first;
  }
  if (present <= 1) {
    return first;  // one range alone passes (or none: no depth)
  }
  // Usually every value agrees with the first: then it has all the support.
  const std::int32_t firstTol = tolerance.at(first);
  bool all = true;
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t d = std::int32_t{centre[i]} - first;
    all = all && (centre[i] == kNoDepth || (d < 0 ? -d : d) <= firstTol);
  }
  if (all) {
    return first;
  }
  int bestSupport = 0;
  std::uint16_t best = kNoDepth;
  for (std::size_t i = 0; i < n; ++i) {
    if (centre[i] == kNoDepth) {
      continue;
    }
    const std::int32_t tol = tolerance.at(centre[i]);
    int support = 0;
    for (std::size_t j = 0; j < n; ++j) {
      const std::int32_t d = std::int32_t{centre[j]} - centre[i];
      support += centre[j] != kNoDepth && (d < 0 ? -d : d) <= tol ? 1 : 0;
    }
    if (support > bestSupport) {
      bestSupport = support;
      best = centre[i];
    }
  }
  return 2 * bestSupport > present ? best : kNoDepth;
}

template <bool kReference>
Result<void> merge(std::span<const ConstDepthPlane> ranges,
                   std::span<const ImageView<const std::uint8_t>> confidences, DepthPlane out,
                   ImageView<std::uint8_t>* outConfidence, const DepthTolerance& tolerance,
                   RowBand rows) {
  if (ranges.empty() || ranges.size() > static_cast<std::size_t>(kMaxRanges)) {
    return fail(Errc::kInvalidArgument, "merge: 1 to 8 range images");
  }
  if (tolerance.minUnits < 0 || tolerance.permille < 0 || tolerance.permille > 1000) {
    return fail(Errc::kInvalidArgument, "merge: tolerance minUnits >= 0, permille 0 to 1000");
  }
  const int w = out.width();
  const int h = out.height();
  for (const ConstDepthPlane& r : ranges) {
    if (r.width() != w || r.height() != h) {
      return fail(Errc::kSizeMismatch, "merge: range images must have the output's size");
    }
  }
  if (outConfidence != nullptr) {
    if (confidences.size() != ranges.size()) {
      return fail(Errc::kSizeMismatch, "merge: one confidence plane per range image");
    }
    if (outConfidence->width() != w || outConfidence->height() != h) {
      return fail(Errc::kSizeMismatch, "merge: confidence planes must have the output's size");
    }
    for (const ImageView<const std::uint8_t>& c : confidences) {
      if (c.width() != w || c.height() != h) {
        return fail(Errc::kSizeMismatch, "merge: confidence planes must have the output's size");
      }
    }
  }
  const std::size_t n = ranges.size();
  // The chosen members are gathered at the front of `chosen`. The reference gathers each new
  // set in `next` and copies it in when the fold keeps it (alone or in a union); the schedule
  // gathers it right behind the chosen members, where a union already has it. A full window the
  // schedule keeps whole stays ungathered (`lazy`: its range) until a union needs its values.
  std::array<std::uint16_t, kMaxValues> chosen{};
  std::array<std::uint16_t, kWindow> next{};
  std::array<std::uint16_t, kMaxRanges> centre{};
  std::array<ChunkColumns, kMaxRanges> columns{};
  const int yEnd = rows.end < h ? rows.end : h;
  for (int y = rows.begin > 0 ? rows.begin : 0; y < yEnd; ++y) {
    std::uint16_t* o = out.rowPtr(y);
    std::uint8_t* oc = outConfidence != nullptr ? outConfidence->rowPtr(y) : nullptr;
    const int y0 = y > 0 ? y - 1 : 0;
    const int y1 = y + 1 < h ? y + 1 : h - 1;
    const bool innerRow = !kReference && y > 0 && y + 1 < h;
    for (int cx = 0; cx < w; cx += kChunk) {
      const int cxEnd = cx + kChunk < w ? cx + kChunk : w;
      if (innerRow) {
        for (std::size_t i = 0; i < n; ++i) {
          fillColumns(ranges[i], y, cx, cx > 0 ? cx - 1 : 0, cxEnd < w ? cxEnd : w - 1, columns[i]);
        }
      }
      for (int x = cx; x < cxEnd; ++x) {
        o[x] = kNoDepth;
        if (oc != nullptr) {
          oc[x] = 0;
        }
        std::uint32_t any = 0;
        for (std::size_t i = 0; i < n; ++i) {
          centre[i] = ranges[i].rowPtr(y)[x];
          any |= centre[i];
        }
        if (!kReference && any == kNoDepth) {
          continue;
        }
        const std::uint16_t ref = reference(centre, n, tolerance);
        if (ref == kNoDepth) {
          continue;
        }
        // z within [ref − tol, ref + tol] and not kNoDepth, in one unsigned comparison.
        const std::int32_t tol = tolerance.at(ref);
        const std::int32_t low = ref > tol ? ref - tol : 1;
        const auto span = static_cast<std::uint32_t>(ref + tol - low);
        const auto agrees = [low, span](std::uint16_t z) {
          return static_cast<std::uint32_t>(std::int32_t{z} - low) <= span;
        };
        const int x0 = x > 0 ? x - 1 : 0;
        const int x1 = x + 1 < w ? x + 1 : w - 1;
        const bool inner = innerRow && x > 0 && x + 1 < w;
        const auto windowColumns = [&](std::size_t i) {
          return &columns[i][static_cast<std::size_t>(x - cx)];
        };
        Set best;
        std::size_t lazy = kMaxRanges;  // none
        std::int32_t error = 255;
        int agreeing = 0;
        for (std::size_t i = 0; i < n; ++i) {
          if (centre[i] != kNoDepth && !agrees(centre[i])) {
            continue;  // outvoted
          }
          if (oc != nullptr && centre[i] != kNoDepth) {
            const std::int32_t e = 255 - confidences[i].rowPtr(y)[x];
            error = e < error ? e : error;
            ++agreeing;
          }
          const ConstDepthPlane& r = ranges[i];
          std::uint16_t* gathered =
              kReference ? next.data() : chosen.data() + static_cast<std::size_t>(best.count);
          Set set;
          // The schedule takes a full 3 × 3 window that agrees throughout without a branch per
          // value: its columns' extremes tell.
          const bool full = inner && fullWindow(windowColumns(i), low, span, set);
          if (!full) {
            for (int yy = y0; yy <= y1; ++yy) {
              const std::uint16_t* row = r.rowPtr(yy);
              for (int xx = x0; xx <= x1; ++xx) {
                const std::uint16_t z = row[xx];
                if (agrees(z)) {
                  gathered[set.count++] = z;
                  set.sum += z;
                  set.sumSquares += std::int64_t{z} * z;
                }
              }
            }
          }
          if (set.count == 0) {
            continue;
          }
          int keep = 0;  // −1: the running choice, 1: the new set, 0: both
          if (best.count == 0 || set.count - best.count > 3) {
            keep = 1;
          } else if (best.count - set.count > 3) {
            keep = -1;
          } else {
            keep = compareVariance(best, set);
          }
          if (keep < 0) {
            continue;
          }
          const auto at = static_cast<std::size_t>(keep == 0 ? best.count : 0);
          if (keep == 0 && lazy < kMaxRanges) {
            gatherWindow(ranges[lazy], x, y, chosen.data());
          }
          if (full) {
            if (keep == 0) {
              gatherWindow(r, x, y, chosen.data() + at);
            }
          } else if (gathered != chosen.data() + at) {
            // Ascending: where the schedule moves a set to the front, the ranges may overlap.
            for (std::size_t k = 0; k < static_cast<std::size_t>(set.count); ++k) {
              chosen[at + k] = gathered[k];
            }
          }
          lazy = keep == 1 && full ? i : kMaxRanges;
          best = keep == 0 ? Set{best.count + set.count, best.sum + set.sum,
                                 best.sumSquares + set.sumSquares}
                           : set;
        }
        const auto count = static_cast<std::size_t>(best.count);
        if constexpr (kReference) {
          o[x] = medianBySorting(chosen, count);
        } else {
          o[x] = lazy < kMaxRanges ? medianOfColumns(windowColumns(lazy))
                                   : medianBySelection(chosen, count);
        }
        if (oc != nullptr) {
          const std::int32_t e =
              (error * kInverseSqrtQ8[static_cast<std::size_t>(agreeing)] + 128) >> 8;
          oc[x] = static_cast<std::uint8_t>(255 - (e > 254 ? 254 : e));
        }
      }
    }
  }
  return {};
}

}  // namespace

Result<void> mergeRanges(std::span<const ConstDepthPlane> ranges, DepthPlane out,
                         const DepthTolerance& tolerance) {
  return merge<false>(ranges, {}, out, nullptr, tolerance, {});
}

Result<void> mergeRanges(std::span<const ConstDepthPlane> ranges,
                         std::span<const ImageView<const std::uint8_t>> confidences, DepthPlane out,
                         ImageView<std::uint8_t> outConfidence, const DepthTolerance& tolerance,
                         RowBand rows) {
  return merge<false>(ranges, confidences, out, &outConfidence, tolerance, rows);
}

Result<void> mergeRangesReference(std::span<const ConstDepthPlane> ranges,
                                  std::span<const ImageView<const std::uint8_t>> confidences,
                                  DepthPlane out, ImageView<std::uint8_t> outConfidence,
                                  const DepthTolerance& tolerance) {
  return merge<true>(ranges, confidences, out, &outConfidence, tolerance, {});
}

}  // namespace smx::algo
