// The median-variant merge (range_merge.hpp; paper §4.2, "data merging stage": the ranges of
// the separated patterns merged per image). merge<true> is the plain scalar definition,
// merge<false> the schedule: the same sets and median, reached with fewer steps (pixels without
// depth passed over; each chunk of a row's 3 × 3 windows, their extremes, sums, variance and
// median, formed in vector lanes from 3 × 1 columns computed once for the three windows that
// hold them; pixels whose windows are each empty or full and agreeing decided from those alone,
// a chunk at a time in vector lanes; otherwise sets gathered in place and the median by
// selection instead of sorting).
#include "smx/algo/range_merge.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

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

// The schedule's 3 × 3 windows of one range along one chunk of a row, each from the three 3 × 1
// columns it holds (every column computed once for the three windows): extremes, the median of
// nine, the sum and 9·Σz² − (Σz)², which orders two full windows' variances as compareVariance()
// does (equal counts: its n² factors cancel). That spread is Σ over pairs of (z_i − z_j)², at
// most 20·(hi − lo)² for nine values, so in uint32 arithmetic (modulo 2^32) it is exact wherever
// hi − lo ≤ kMaxExactSpan; only windows within such a span are ever compared by it.
constexpr int kChunk = 64;
constexpr std::uint32_t kMaxExactSpan = 14654;  // 20 · 14654² < 2^32 ≤ 20 · 14655²
struct ChunkWindows {
  std::array<std::uint16_t, kChunk> lo;
  std::array<std::uint16_t, kChunk> hi;
  std::array<std::uint16_t, kChunk> median;
  std::array<std::int32_t, kChunk> sum;
  std::array<std::uint32_t, kChunk> spread;
};

std::int32_t medianOfThree(std::int32_t a, std::int32_t b, std::int32_t c) {
  return std::max(std::min(a, b), std::min(std::max(a, b), c));
}

// The windows of range r around inner pixels [xBegin, xEnd) of inner row y, window x at index
// x − cx. Of nine values, the median is the median of the largest column minimum, the median
// column median and the smallest column maximum.
void fillWindows(const ConstDepthPlane& r, int y, int cx, int xBegin, int xEnd,
                 ChunkWindows& windows) {
  constexpr std::size_t kColumns = kChunk + 2;
  std::array<std::int32_t, kColumns> lo{};
  std::array<std::int32_t, kColumns> mid{};
  std::array<std::int32_t, kColumns> hi{};
  std::array<std::int32_t, kColumns> sum{};
  std::array<std::uint32_t, kColumns> squares{};  // modulo 2^32
  const std::uint16_t* above = r.rowPtr(y - 1) + xBegin - 1;
  const std::uint16_t* at = r.rowPtr(y) + xBegin - 1;
  const std::uint16_t* below = r.rowPtr(y + 1) + xBegin - 1;
  const auto columns = static_cast<std::size_t>(xEnd - xBegin) + 2;
  for (std::size_t c = 0; c < columns; ++c) {
    const std::int32_t a = above[c];
    const std::int32_t b = at[c];
    const std::int32_t d = below[c];
    lo[c] = std::min(std::min(a, b), d);
    hi[c] = std::max(std::max(a, b), d);
    sum[c] = a + b + d;
    mid[c] = sum[c] - lo[c] - hi[c];
    const auto ua = static_cast<std::uint32_t>(a);
    const auto ub = static_cast<std::uint32_t>(b);
    const auto ud = static_cast<std::uint32_t>(d);
    squares[c] = ua * ua + ub * ub + ud * ud;
  }
  const auto first = static_cast<std::size_t>(xBegin - cx);
  for (std::size_t c = 0; c + 2 < columns; ++c) {
    const std::size_t k = first + c;
    // Values, not references into the arrays: the vectoriser takes no select of addresses.
    const std::int32_t lo0 = lo[c];
    const std::int32_t lo1 = lo[c + 1];
    const std::int32_t lo2 = lo[c + 2];
    const std::int32_t hi0 = hi[c];
    const std::int32_t hi1 = hi[c + 1];
    const std::int32_t hi2 = hi[c + 2];
    const std::int32_t lows = std::max(std::max(lo0, lo1), lo2);
    const std::int32_t highs = std::min(std::min(hi0, hi1), hi2);
    const std::int32_t mids = medianOfThree(mid[c], mid[c + 1], mid[c + 2]);
    const std::int32_t s = sum[c] + sum[c + 1] + sum[c + 2];
    const std::uint32_t q = squares[c] + squares[c + 1] + squares[c + 2];
    const auto us = static_cast<std::uint32_t>(s);
    windows.lo[k] = static_cast<std::uint16_t>(std::min(std::min(lo0, lo1), lo2));
    windows.hi[k] = static_cast<std::uint16_t>(std::max(std::max(hi0, hi1), hi2));
    windows.median[k] = static_cast<std::uint16_t>(medianOfThree(lows, mids, highs));
    windows.sum[k] = s;
    windows.spread[k] = kWindow * q - us * us;
  }
}

// Whether all nine values of window k lie in [low, low + span] (so none is kNoDepth).
bool agreesThroughout(const ChunkWindows& windows, std::size_t k, std::int32_t low,
                      std::uint32_t span) {
  return windows.lo[k] >= low && static_cast<std::uint32_t>(windows.hi[k] - low) <= span;
}

// Window k as a set when it agrees throughout and its spread is exact; false otherwise.
bool fullWindow(const ChunkWindows& windows, std::size_t k, std::int32_t low, std::uint32_t span,
                Set& set) {
  if (span > kMaxExactSpan || !agreesThroughout(windows, k, low, span)) {
    return false;
  }
  const std::int64_t sum = windows.sum[k];
  set = {kWindow, sum, (std::int64_t{windows.spread[k]} + sum * sum) / kWindow};
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

// reference() where two or more ranges have a value.
std::uint16_t voteForReference(const std::array<std::uint16_t, kMaxRanges>& centre, std::size_t n,
                               int present, std::uint16_t first, const DepthTolerance& tolerance) {
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

// The reference value at a pixel from the ranges' centre values (0: none), of which `present`
// are values and `first` is the first, or 0 when no value has a strict majority within the
// tolerance. One range alone passes (or none: no depth) without a vote.
std::uint16_t reference(const std::array<std::uint16_t, kMaxRanges>& centre, std::size_t n,
                        int present, std::uint16_t first, const DepthTolerance& tolerance) {
  return present <= 1 ? first : voteForReference(centre, n, present, first, tolerance);
}

// The merged confidence from the smallest predicted error among the agreeing ranges.
// The same from kInverseSqrtQ8[agreeing] (decideChunk() selects it in vector lanes).
std::int32_t confidenceOfInverse(std::int32_t error, std::int32_t inverseSqrtQ8) {
  return 255 - std::min((error * inverseSqrtQ8 + 128) >> 8, 254);
}

std::uint8_t mergedConfidence(std::int32_t error, int agreeing) {
  return static_cast<std::uint8_t>(
      confidenceOfInverse(error, kInverseSqrtQ8[static_cast<std::size_t>(agreeing)]));
}

// Where the merged confidence goes, with the ranges' confidences at the pixel (none: no
// confidence output).
struct ConfidenceAt {
  const std::array<const std::uint8_t*, kMaxRanges>* rows = nullptr;  // the ranges' at the row
  int x = 0;
  std::uint8_t* out = nullptr;
};

// The schedule's shortcut at an inner pixel where every range's window is either empty or nine
// values agreeing with the reference, and no two full windows' variances tie: the fold then
// keeps one full window whole (counts equal, smaller variance), and the median is that
// window's. False, with nothing written, where the fold would do anything else.
bool mergeFullWindows(std::span<const ChunkWindows> windows, std::size_t k, std::int32_t low,
                      std::uint32_t span, std::uint16_t& out, const ConfidenceAt& confidence) {
  if (span > kMaxExactSpan) {
    return false;
  }
  const ChunkWindows* best = nullptr;
  std::int32_t error = 255;
  int agreeing = 0;
  for (std::size_t i = 0; i < windows.size(); ++i) {
    const ChunkWindows& w = windows[i];
    if (w.hi[k] == kNoDepth) {
      continue;  // empty: no value at the pixel either, so no part in the confidence
    }
    if (!agreesThroughout(w, k, low, span)) {
      return false;
    }
    if (confidence.out != nullptr) {
      const std::int32_t e = 255 - (*confidence.rows)[i][confidence.x];
      error = e < error ? e : error;
      ++agreeing;
    }
    if (best == nullptr || w.spread[k] < best->spread[k]) {
      best = &w;
    } else if (w.spread[k] == best->spread[k]) {
      return false;  // a tie: the fold takes the union
    }
  }
  if (best == nullptr) {
    return false;
  }
  out = best->median[k];
  if (confidence.out != nullptr) {
    *confidence.out = mergedConfidence(error, agreeing);
  }
  return true;
}

// mergeFullWindows() for every inner pixel [xBegin, xEnd) of a chunk at once, in vector lanes
// (index x − cx): where no range has a value at the pixel, or where every range's window is
// empty or agrees throughout with the first range's value (so every value at the pixel does:
// the vote's reference is that first value) without a tie, the pixel's output and confidence
// are written and its `decided` lane set. The rest is left to the per-pixel path.
struct ChunkDecision {
  std::array<std::int32_t, kChunk> first;
  std::array<std::int32_t, kChunk> low;
  std::array<std::uint32_t, kChunk> span;
  std::array<std::int32_t, kChunk> open;  // no window disagrees, no tie yet
  std::array<std::uint32_t, kChunk> spread;
  std::array<std::int32_t, kChunk> median;
  std::array<std::int32_t, kChunk> error;
  std::array<std::int32_t, kChunk> agreeing;
  std::array<std::int32_t, kChunk> inverse;  // kInverseSqrtQ8[agreeing]
  std::array<std::uint8_t, kChunk> decided;
};

struct ChunkInputs {
  std::span<const ChunkWindows> windows;
  std::span<const std::uint16_t* const> centreRows;
  std::span<const std::uint8_t* const> confidenceRows;  // empty: no confidence output
  int cx = 0;
  int xBegin = 0;
  int xEnd = 0;
};

void decideChunk(const ChunkInputs& in, const DepthTolerance& tolerance, std::uint16_t* out,
                 std::uint8_t* outConfidence, ChunkDecision& d) {
  const auto kBegin = static_cast<std::size_t>(in.xBegin - in.cx);
  const auto kEnd = static_cast<std::size_t>(in.xEnd - in.cx);
  const auto cx = static_cast<std::size_t>(in.cx);
  for (std::size_t k = kBegin; k < kEnd; ++k) {
    d.first[k] = 0;
  }
  for (const std::uint16_t* centre : in.centreRows) {
    for (std::size_t k = kBegin; k < kEnd; ++k) {
      const std::int32_t f = d.first[k];
      const std::int32_t z = centre[cx + k];  // loaded either way: no branch
      d.first[k] = f != 0 ? f : z;
    }
  }
  const auto permille = static_cast<std::uint32_t>(tolerance.permille);
  const std::int32_t minUnits = tolerance.minUnits;
  for (std::size_t k = kBegin; k < kEnd; ++k) {
    // DepthTolerance::at(), unsigned (the same for z ≥ 0): the division vectorises.
    const std::int32_t f = d.first[k];
    const auto relative =
        static_cast<std::int32_t>(static_cast<std::uint32_t>(f) * permille / 1000);
    const std::int32_t tol = relative > minUnits ? relative : minUnits;
    const std::int32_t low = f > tol ? f - tol : 1;
    const auto span = static_cast<std::uint32_t>(f + tol - low);
    d.low[k] = low;
    d.span[k] = span;
    d.open[k] = span <= kMaxExactSpan ? 1 : 0;
    d.spread[k] = 0xffffffffU;
    d.median[k] = 0;
    d.error[k] = 255;
    d.agreeing[k] = 0;
  }
  for (std::size_t i = 0; i < in.windows.size(); ++i) {
    const ChunkWindows& w = in.windows[i];
    for (std::size_t k = kBegin; k < kEnd; ++k) {
      const std::int32_t lo = w.lo[k];
      const std::int32_t hi = w.hi[k];
      const std::int32_t low = d.low[k];
      const std::uint32_t span = d.span[k];
      const std::uint32_t spread = w.spread[k];
      const std::uint32_t best = d.spread[k];
      const std::int32_t median = w.median[k];
      const std::int32_t bestMedian = d.median[k];
      // Bitwise, not short-circuit operators: every lane computes everything.
      const std::int32_t full = hi != kNoDepth ? 1 : 0;
      const std::int32_t agrees =
          (lo >= low ? 1 : 0) & (static_cast<std::uint32_t>(hi - low) <= span ? 1 : 0);
      const std::int32_t smaller = full & (spread < best ? 1 : 0);
      const std::int32_t tie = full & (spread == best ? 1 : 0);
      d.open[k] &= (agrees | (full ^ 1)) & (tie ^ 1);
      // Selects as arithmetic (an empty window's spread as the largest): GCC if-converts these.
      d.spread[k] = std::min(best, spread | static_cast<std::uint32_t>(full - 1));
      d.median[k] = (median & -smaller) | (bestMedian & (smaller - 1));
      d.agreeing[k] += full;
    }
    if (!in.confidenceRows.empty()) {
      const std::uint8_t* confidence = in.confidenceRows[i] + cx;
      for (std::size_t k = kBegin; k < kEnd; ++k) {
        // An empty window's error as 256 or more: it never counts.
        const std::int32_t empty = w.hi[k] == kNoDepth ? 1 : 0;
        const std::int32_t e = 255 - std::int32_t{confidence[k]} + (empty << 8);
        d.error[k] = std::min(d.error[k], e);
      }
    }
  }
  for (std::size_t k = kBegin; k < kEnd; ++k) {
    const std::int32_t depth = d.first[k] != kNoDepth ? 1 : 0;
    d.decided[k] = static_cast<std::uint8_t>((depth ^ 1) | d.open[k]);
    out[cx + k] = static_cast<std::uint16_t>(d.median[k] & -depth);
  }
  if (outConfidence != nullptr) {
    // kInverseSqrtQ8[agreeing] without a gather: one pass per possible count.
    for (std::size_t k = kBegin; k < kEnd; ++k) {
      d.inverse[k] = 0;
    }
    for (std::size_t a = 1; a <= in.windows.size(); ++a) {
      const std::int32_t inverse = kInverseSqrtQ8[a];
      const auto count = static_cast<std::int32_t>(a);
      for (std::size_t k = kBegin; k < kEnd; ++k) {
        d.inverse[k] |= inverse & -(d.agreeing[k] == count ? 1 : 0);
      }
    }
    for (std::size_t k = kBegin; k < kEnd; ++k) {
      const std::int32_t depth = d.first[k] != kNoDepth ? 1 : 0;
      outConfidence[cx + k] =
          static_cast<std::uint8_t>(confidenceOfInverse(d.error[k], d.inverse[k]) & -depth);
    }
  }
}

// Whether decideChunk() decided lanes k … k + 7.
bool allDecided8(const ChunkDecision& d, std::size_t k) {
  std::uint64_t lanes = 0;
  std::memcpy(&lanes, &d.decided[k], sizeof lanes);
  return lanes == 0x0101010101010101U;
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
  std::array<ChunkWindows, kMaxRanges> windows{};
  ChunkDecision decision{};
  std::array<const std::uint16_t*, kMaxRanges> centreRows{};
  std::array<const std::uint8_t*, kMaxRanges> confidenceRows{};
  const int yEnd = rows.end < h ? rows.end : h;
  for (int y = rows.begin > 0 ? rows.begin : 0; y < yEnd; ++y) {
    std::uint16_t* o = out.rowPtr(y);
    std::uint8_t* oc = outConfidence != nullptr ? outConfidence->rowPtr(y) : nullptr;
    const int y0 = y > 0 ? y - 1 : 0;
    const int y1 = y + 1 < h ? y + 1 : h - 1;
    const bool innerRow = !kReference && y > 0 && y + 1 < h;
    for (std::size_t i = 0; i < n; ++i) {
      centreRows[i] = ranges[i].rowPtr(y);
      confidenceRows[i] = oc != nullptr ? confidences[i].rowPtr(y) : nullptr;
    }
    for (int cx = 0; cx < w; cx += kChunk) {
      const int cxEnd = cx + kChunk < w ? cx + kChunk : w;
      const int innerBegin = cx > 0 ? cx : 1;
      const int innerEnd = cxEnd < w ? cxEnd : w - 1;
      if (innerRow && innerBegin < innerEnd) {
        for (std::size_t i = 0; i < n; ++i) {
          fillWindows(ranges[i], y, cx, innerBegin, innerEnd, windows[i]);
        }
        const ChunkInputs chunk{{windows.data(), n},
                                {centreRows.data(), n},
                                oc != nullptr
                                    ? std::span<const std::uint8_t* const>{confidenceRows.data(), n}
                                    : std::span<const std::uint8_t* const>{},
                                cx,
                                innerBegin,
                                innerEnd};
        decideChunk(chunk, tolerance, o, oc, decision);
      }
      for (int x = cx; x < cxEnd; ++x) {
        const bool inner = innerRow && x > 0 && x + 1 < w;
        const auto k = static_cast<std::size_t>(x - cx);
        if (inner && decision.decided[k] != 0) {
          if (k % 8 == 0 && x + 8 <= innerEnd && allDecided8(decision, k)) {
            x += 7;  // and the ++x: eight decided pixels passed in one test
          }
          continue;
        }
        o[x] = kNoDepth;
        if (oc != nullptr) {
          oc[x] = 0;
        }
        int present = 0;
        std::uint16_t first = kNoDepth;
        for (std::size_t i = 0; i < n; ++i) {
          centre[i] = centreRows[i][x];
          present += centre[i] != kNoDepth ? 1 : 0;
          first = first == kNoDepth ? centre[i] : first;
        }
        if (!kReference && present == 0) {
          continue;
        }
        const std::uint16_t ref = reference(centre, n, present, first, tolerance);
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
        // With the first value as the reference, decideChunk() has already tried this shortcut.
        if (inner && ref != first &&
            mergeFullWindows(
                {windows.data(), n}, k, low, span, o[x],
                oc != nullptr ? ConfidenceAt{&confidenceRows, x, &oc[x]} : ConfidenceAt{})) {
          continue;
        }
        const int x0 = x > 0 ? x - 1 : 0;
        const int x1 = x + 1 < w ? x + 1 : w - 1;
        Set best;
        std::size_t lazy = kMaxRanges;  // none
        std::int32_t error = 255;
        int agreeing = 0;
        for (std::size_t i = 0; i < n; ++i) {
          if (centre[i] != kNoDepth && !agrees(centre[i])) {
            continue;  // outvoted
          }
          if (oc != nullptr && centre[i] != kNoDepth) {
            const std::int32_t e = 255 - confidenceRows[i][x];
            error = e < error ? e : error;
            ++agreeing;
          }
          const ConstDepthPlane& r = ranges[i];
          std::uint16_t* gathered =
              kReference ? next.data() : chosen.data() + static_cast<std::size_t>(best.count);
          Set set;
          // The schedule takes a full 3 × 3 window that agrees throughout without a branch per
          // value: its extremes tell.
          const bool full = inner && fullWindow(windows[i], k, low, span, set);
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
            for (std::size_t j = 0; j < static_cast<std::size_t>(set.count); ++j) {
              chosen[at + j] = gathered[j];
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
          o[x] = lazy < kMaxRanges ? windows[lazy].median[k] : medianBySelection(chosen, count);
        }
        if (oc != nullptr) {
          oc[x] = mergedConfidence(error, agreeing);
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
