// The median-variant merge (range_merge.hpp; paper §4.2, "data merging stage": the ranges of
// the separated patterns merged per image). This scalar code is the reference; no separate
// schedule exists.
#include "smx/algo/range_merge.hpp"

#include <array>
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
std::uint16_t median(std::array<std::uint16_t, kMaxValues>& v, std::size_t n) {
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

}  // namespace

Result<void> mergeRanges(std::span<const ConstDepthPlane> ranges, DepthPlane out) {
  if (ranges.empty() || ranges.size() > static_cast<std::size_t>(kMaxRanges)) {
    return fail(Errc::kInvalidArgument, "merge: 1 to 8 range images");
  }
  const int w = out.width();
  const int h = out.height();
  for (const ConstDepthPlane& r : ranges) {
    if (r.width() != w || r.height() != h) {
      return fail(Errc::kSizeMismatch, "merge: range images must have the output's size");
    }
  }
  // The chosen members are gathered at the front of `chosen`; each new set is gathered behind
  // them in `next`, and copied in when the fold keeps it (alone or in a union).
  std::array<std::uint16_t, kMaxValues> chosen{};
  std::array<std::uint16_t, kWindow> next{};
  for (int y = 0; y < h; ++y) {
    std::uint16_t* o = out.rowPtr(y);
    const int y0 = y > 0 ? y - 1 : 0;
    const int y1 = y + 1 < h ? y + 1 : h - 1;
    for (int x = 0; x < w; ++x) {
      o[x] = kNoDepth;
      bool centre = false;
      for (const ConstDepthPlane& r : ranges) {
        centre = centre || r.rowPtr(y)[x] != kNoDepth;
      }
      if (!centre) {
        continue;
      }
      const int x0 = x > 0 ? x - 1 : 0;
      const int x1 = x + 1 < w ? x + 1 : w - 1;
      Set best;
      for (const ConstDepthPlane& r : ranges) {
        Set set;
        for (int yy = y0; yy <= y1; ++yy) {
          const std::uint16_t* row = r.rowPtr(yy);
          for (int xx = x0; xx <= x1; ++xx) {
            const std::uint16_t z = row[xx];
            if (z != kNoDepth) {
              next[static_cast<std::size_t>(set.count++)] = z;
              set.sum += z;
              set.sumSquares += std::int64_t{z} * z;
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
        for (std::size_t i = 0; i < static_cast<std::size_t>(set.count); ++i) {
          chosen[at + i] = next[i];
        }
        best = keep == 0 ? Set{best.count + set.count, best.sum + set.sum,
                               best.sumSquares + set.sumSquares}
                         : set;
      }
      o[x] = median(chosen, static_cast<std::size_t>(best.count));
    }
  }
  return {};
}

}  // namespace smx::algo
