// Multi-layer decoding (stripe_decode.hpp; paper §4.1–4.2: the colour-stripe permutation code
// matched along the separated boundaries, multi-layer decoding after its [31]). This scalar code
// is the reference; where a step has a faster schedule, the same template holds both
// (kReference): the schedule passes over work whose result is known or reaches the same result
// by a shorter way (docs/decode.md "Reference and schedules"). Numerics:
//   Positions  Q8 pixels (int32); a boundary lies at its pixel centre + offset (Q8) along the
//              encoding direction of that pixel, whose unit vector is Q1.14 (demux::UnitTable);
//              the shift offset·u is rounded half up to Q8 once per frame (|shift| ≤ 128).
//   Distances  along an axis: dot(ΔQ8, uQ14) >> 14 in int64, so any Δ within the image is exact
//              before the shift; the shift rounds towards −∞ (≤ 1/256 px).
//   Walks      half-pixel steps: (u >> 7) in Q8, looking at the 2×2 pixels around each sample.
//   Coordinate s = level · 2^16 + (dFirst · 2^16) / dBetween, int64, truncated (< 2^-16 stripe);
//              0 ≤ dFirst < dBetween, so s stays within [level, level + 1) · 2^16.
#include "smx/algo/stripe_decode.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>

#include "decode/decode_geometry.hpp"
#include "demux_kernels.hpp"
#include "smx/algo/stripe_code.hpp"

namespace smx::algo {

using decode::along;
using decode::flat;
using decode::Hit;
using decode::kNone;
using decode::PointQ8;
using decode::Unit;
using decode::unitOf;
using decode::walk;
using decode::walkSkippingEmpty;

namespace {

constexpr int kChainEachWay = stripe::kWindowTransitions - 1;  // 5: every window holding a pixel

// The level most windows found and its count (the first of equals); only a strict majority is
// used.
std::pair<int, int> mostFound(const std::array<std::int16_t, stripe::kWindowTransitions>& found,
                              int count) {
  int best = 0;
  int bestVotes = 0;
  for (int a = 0; a < count; ++a) {
    int n = 0;
    for (int c = 0; c < count; ++c) {
      n += found[static_cast<std::size_t>(c)] == found[static_cast<std::size_t>(a)] ? 1 : 0;
    }
    if (n > bestVotes) {
      best = found[static_cast<std::size_t>(a)];
      bestVotes = n;
    }
  }
  return {best, bestVotes};
}

// The same where it matters, in two passes: a strict majority is unique, and Boyer–Moore's
// candidate is it when there is one; otherwise its count is no majority either.
std::pair<int, int> majorityFound(const std::array<std::int16_t, stripe::kWindowTransitions>& found,
                                  int count) {
  int candidate = 0;
  int weight = 0;
  for (int a = 0; a < count; ++a) {
    const int level = found[static_cast<std::size_t>(a)];
    if (weight == 0) {
      candidate = level;
    }
    weight += level == candidate ? 1 : -1;
  }
  int votes = 0;
  for (int a = 0; a < count; ++a) {
    votes += found[static_cast<std::size_t>(a)] == candidate ? 1 : 0;
  }
  return {candidate, votes};
}

// Per boundary code (transition + 1; 0: none): whether its transition is a plus one, and its
// first colour's index, for the vote's packed chains.
constexpr std::array<unsigned, stripe::kTransitions + 1> kPlusOfCode = [] {
  std::array<unsigned, stripe::kTransitions + 1> table{};
  for (std::size_t t = 0; t < stripe::kTransitions; ++t) {
    table[t + 1] = stripe::isPlus(static_cast<stripe::Transition>(t)) ? 1U : 0U;
  }
  return table;
}();
constexpr std::array<unsigned, stripe::kTransitions + 1> kFromOfCode = [] {
  std::array<unsigned, stripe::kTransitions + 1> table{};
  for (std::size_t t = 0; t < stripe::kTransitions; ++t) {
    table[t + 1] =
        static_cast<unsigned>(stripe::indexOf(stripe::from(static_cast<stripe::Transition>(t))));
  }
  return table;
}();
constexpr unsigned kWindowMask = (1U << stripe::kWindowTransitions) - 1;

Result<void> validate(int width, int height, const DecodeParams& p) {
  if (width < 1 || height < 1 || width > 8192 || height > 8192) {
    return fail(Errc::kInvalidArgument, "decode: image size must be 1 to 8192 pixels per side");
  }
  if (p.maxGapPx < 1 || p.maxGapPx > 64 || p.minSeparationQ8 < 0 || p.minSeparationQ8 > 64 * 256 ||
      p.minCurveVotes < 1 || p.minCurveVotes > 1 << 20) {
    return fail(Errc::kInvalidArgument,
                "decode: maxGapPx 1 to 64, minSeparationQ8 0 to 16384, minCurveVotes >= 1");
  }
  if (p.maxNeighbourDisagreePct < 0 || p.maxNeighbourDisagreePct > 100) {
    return fail(Errc::kInvalidArgument, "decode: maxNeighbourDisagreePct must be 0 to 100");
  }
  if (p.maxGapRatioPct != 0 && (p.maxGapRatioPct < 101 || p.maxGapRatioPct > 400)) {
    return fail(Errc::kInvalidArgument, "decode: maxGapRatioPct must be 0 (off) or 101 to 400");
  }
  return {};
}

}  // namespace

template <class Carver>
Result<void> StripeDecoder::carve(Carver& carver) {
  const std::size_t pixels = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  Result<void> ok;
  const auto step = [&ok](Result<void> r) {
    if (ok && !r) {
      ok = r;
    }
  };
  step(carveSpan(carver, units_, 1));
  step(carveSpan(carver, line_, static_cast<std::size_t>(width_ > height_ ? width_ : height_)));
  step(carveSpan(carver, axis_, pixels));
  step(carveSpan(carver, boundaries_, pixels));
  step(carveSpan(carver, code_, pixels));
  step(carveSpan(carver, shift_, pixels));
  step(carveSpan(carver, next_, pixels));
  step(carveSpan(carver, prev_, pixels));
  step(carveSpan(carver, gapNext_, pixels));
  step(carveSpan(carver, gapPrev_, pixels));
  step(carveSpan(carver, parent_, pixels));
  step(carveSpan(carver, weight_, pixels));
  step(carveSpan(carver, total_, pixels));
  step(carveSpan(carver, candidate_, pixels));
  step(carveSpan(carver, votes_, pixels));
  step(carveSpan(carver, own_, pixels));
  step(carveSpan(carver, level_, pixels));
  return ok;
}

Result<std::size_t> StripeDecoder::workspaceBytes(int width, int height,
                                                  const DecodeParams& params) {
  if (auto ok = validate(width, height, params); !ok) {
    return std::unexpected(ok.error());
  }
  StripeDecoder d;
  d.width_ = width;
  d.height_ = height;
  d.params_ = params;
  ArenaSizer sizer;
  if (auto ok = d.carve(sizer); !ok) {
    return std::unexpected(ok.error());
  }
  return sizer.bytes();
}

Result<StripeDecoder> StripeDecoder::create(int width, int height, const DecodeParams& params,
                                            Arena& arena) {
  if (auto ok = validate(width, height, params); !ok) {
    return std::unexpected(ok.error());
  }
  StripeDecoder d;
  d.width_ = width;
  d.height_ = height;
  d.params_ = params;
  const Arena::Marker start = arena.mark();
  if (auto ok = d.carve(arena); !ok) {
    arena.rewind(start);
    return std::unexpected(ok.error());
  }
  d.units_[0].fill();
  for (auto& level : d.level_) {
    level = 0;
  }
  return d;
}

Result<void> StripeDecoder::run(ConstBoundaryPlane boundaries, ConstDirectionPlane directions,
                                StripePlane stripe) {
  const auto sameSize = [this](int w, int h) { return w == width_ && h == height_; };
  if (!sameSize(boundaries.width(), boundaries.height()) ||
      !sameSize(directions.width(), directions.height()) ||
      !sameSize(stripe.width(), stripe.height())) {
    return fail(Errc::kSizeMismatch, "decode: boundary, direction and stripe planes must match");
  }
  stats_ = DecodeStats{};
  prepare(boundaries, directions);
  if (reference_) {
    runSteps<true>(directions, stripe);
  } else {
    runSteps<false>(directions, stripe);
  }
  return {};
}

template <bool kReference>
void StripeDecoder::runSteps(ConstDirectionPlane d, StripePlane stripe) {
  link<kReference>(d);
  vote<kReference>();
  joinCurves<kReference>();
  smoothPositions<kReference>(d);
  fill(d, stripe);
}

// Each boundary's class and sub-pixel shift in flat planes (the walks below read them many
// times), and the list of boundary pixels in ascending order.
void StripeDecoder::prepare(ConstBoundaryPlane b, ConstDirectionPlane d) {
  const demux::UnitTable& units = units_[0];
  // Locals, not the members: the byte stores could alias them.
  const int w = width_;
  const int h = height_;
  std::uint8_t* const code = code_.data();
  Shift* const shift = shift_.data();
  std::int32_t* const list = boundaries_.data();
  std::int32_t count = 0;
  for (int y = 0; y < h; ++y) {
    const Boundary* row = b.rowPtr(y);
    const std::uint16_t* dirs = d.rowPtr(y);
    const auto base = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = base + static_cast<std::size_t>(x);
      code[i] = row[x].transition;
      if (row[x].present()) {
        const Unit u = unitOf(units, dirs[x]);
        shift[i] = {static_cast<std::int16_t>((row[x].offset * u.x + 8192) >> 14),
                    static_cast<std::int16_t>((row[x].offset * u.y + 8192) >> 14)};
        list[count++] = static_cast<std::int32_t>(i);
      }
    }
  }
  stats_.boundaryPixels = count;
}

// f(i) for every boundary pixel i, in ascending order: the reference looks at every pixel, the
// schedule reads the list prepare() made. Steps 1–3 read and write their per-pixel planes only
// at boundary pixels.
template <bool kReference, class F>
void StripeDecoder::eachBoundary(F f) const {
  if constexpr (kReference) {
    for (std::size_t i = 0; i < code_.size(); ++i) {
      if (code_[i] != 0) {
        f(i);
      }
    }
  } else {
    for (const std::int32_t i :
         boundaries_.first(static_cast<std::size_t>(stats_.boundaryPixels))) {
      f(static_cast<std::size_t>(i));
    }
  }
}

// Step 1. From the boundary's sub-pixel position, half-pixel steps along ±axis; the first pixel
// holding a boundary of another class at least minSeparation along the axis is the link
// (boundaries of the same class met first are the same curve seen on a staircase).
template <bool kReference>
void StripeDecoder::link(ConstDirectionPlane d) {
  const demux::UnitTable& units = units_[0];
  const int steps = 2 * params_.maxGapPx;
  const auto w = static_cast<std::size_t>(width_);
  eachBoundary<kReference>([&](std::size_t i) {
    const int x = static_cast<int>(i % w);
    const int y = static_cast<int>(i / w);
    const Unit u = unitOf(units, d.rowPtr(y)[x]);
    const PointQ8 p{x * 256 + shift_[i].x, y * 256 + shift_[i].y};
    for (int sign = -1; sign <= 1; sign += 2) {
      const auto distance = [&](int qx, int qy, std::int32_t q) -> std::int32_t {
        const auto qi = static_cast<std::size_t>(q);
        if (code_[qi] == code_[i]) {
          return -1;
        }
        const PointQ8 qp{qx * 256 + shift_[qi].x, qy * 256 + shift_[qi].y};
        const std::int32_t dist = sign * along(p, qp, u);
        return dist >= params_.minSeparationQ8 ? dist : -1;
      };
      const std::int32_t sx = sign * (u.x >> 7);
      const std::int32_t sy = sign * (u.y >> 7);
      const Hit hit =
          kReference ? walk(code_, width_, height_, p, sx, sy, 1, steps, distance)
                     : walkSkippingEmpty(code_, width_, height_, p, sx, sy, 1, steps, distance);
      (sign > 0 ? next_ : prev_)[i] = hit.at;
      // ≤ (maxGapPx + 2) px ≤ 66 · 256 in Q8.
      (sign > 0 ? gapNext_ : gapPrev_)[i] = static_cast<std::int16_t>(hit.distance);
    }
  });
}

// Step 2. The chain around each pixel (index kChainEachWay is the pixel itself), then every
// window of 6 consecutive transitions in it.
template <bool kReference>
void StripeDecoder::vote() {
  const auto indexOf = [](std::int32_t link) { return static_cast<std::size_t>(link); };  // ≠ kNone
  const auto kindAt = [this](std::size_t i) {
    return static_cast<stripe::Transition>(code_[i] - 1);
  };
  // A link counts when the linked boundary's own link in the opposite direction comes back to
  // the same boundary curve (a pixel of the same class), not to some other boundary.
  const auto linksBack = [&](std::span<const std::int32_t> links, std::size_t from,
                             std::size_t to) {
    const std::int32_t back = links[from];
    return back != kNone && code_[indexOf(back)] == code_[to];
  };
  const auto stepsBack = [&](std::size_t cur, std::size_t n) {
    return stripe::to(kindAt(n)) == stripe::from(kindAt(cur)) && linksBack(next_, n, cur);
  };
  const auto stepsAhead = [&](std::size_t cur, std::size_t n) {
    return stripe::from(kindAt(n)) == stripe::to(kindAt(cur)) && linksBack(prev_, n, cur);
  };
  const auto vote = [&](std::size_t i, std::array<std::int16_t, stripe::kWindowTransitions>& found,
                        int count) {
    const auto [best, bestVotes] =
        kReference ? mostFound(found, count) : majorityFound(found, count);
    // A level only on a strict majority of the pixel's windows.
    if (2 * bestVotes > count) {
      own_[i] = static_cast<std::int16_t>(best);
      votes_[i] = static_cast<std::int16_t>(bestVotes);
      ++stats_.votedPixels;
    }
  };
  if constexpr (kReference) {
    eachBoundary<true>([&](std::size_t i) {
      own_[i] = 0;
      votes_[i] = 0;
      std::array<stripe::Transition, 2 * kChainEachWay + 1> chain{};
      chain[kChainEachWay] = kindAt(i);
      int lo = kChainEachWay;
      for (std::size_t cur = i; lo > 0;) {
        const std::int32_t link = prev_[cur];
        if (link == kNone || !stepsBack(cur, indexOf(link))) {
          break;
        }
        cur = indexOf(link);
        chain[static_cast<std::size_t>(--lo)] = kindAt(cur);
      }
      int hi = kChainEachWay;
      for (std::size_t cur = i; hi < 2 * kChainEachWay;) {
        const std::int32_t link = next_[cur];
        if (link == kNone || !stepsAhead(cur, indexOf(link))) {
          break;
        }
        cur = indexOf(link);
        chain[static_cast<std::size_t>(++hi)] = kindAt(cur);
      }
      // Windows start at j (chain index) with lo ≤ j, j + 5 ≤ hi, j ≤ kChainEachWay ≤ j + 5.
      std::array<std::int16_t, stripe::kWindowTransitions> found{};
      int count = 0;
      for (int j = lo; j <= kChainEachWay && j + stripe::kWindowTransitions - 1 <= hi; ++j) {
        const int index =
            stripe::decodeWindow(std::span<const stripe::Transition, stripe::kWindowTransitions>(
                chain.data() + j, stripe::kWindowTransitions));
        if (index >= 0) {
          found[static_cast<std::size_t>(count++)] =
              static_cast<std::int16_t>(index + (kChainEachWay - j) + 1);
        }
      }
      vote(i, found, count);
    });
    return;
  }
  // The schedule decides each pixel's two steps once, not once per chain through it: bit 0 the
  // step behind, bit 1 the step ahead, in candidate_ (free until step 3 sets it).
  eachBoundary<false>([&](std::size_t i) {
    const bool back = prev_[i] != kNone && stepsBack(i, indexOf(prev_[i]));
    const bool ahead = next_[i] != kNone && stepsAhead(i, indexOf(next_[i]));
    candidate_[i] = static_cast<std::int16_t>((back ? 1 : 0) | (ahead ? 2 : 0));
  });
  // The chain as two words instead of an array of transitions: bit k of `plus` set when chain[k]
  // is a plus transition, bits 2k, 2k + 1 of `colours` its first colour. Each window's code is
  // read from them: the links above chained the colours, so no window can fail decodeWindow's
  // chain check.
  eachBoundary<false>([&](std::size_t i) {
    own_[i] = 0;
    votes_[i] = 0;
    unsigned plus = 0;
    unsigned colours = 0;
    const auto put = [&](std::size_t pixel, int k) {
      plus |= kPlusOfCode[code_[pixel]] << static_cast<unsigned>(k);
      colours |= kFromOfCode[code_[pixel]] << static_cast<unsigned>(2 * k);
    };
    put(i, kChainEachWay);
    int lo = kChainEachWay;
    for (std::size_t cur = i; lo > 0 && (candidate_[cur] & 1) != 0;) {
      cur = indexOf(prev_[cur]);
      put(cur, --lo);
    }
    int hi = kChainEachWay;
    for (std::size_t cur = i; hi < 2 * kChainEachWay && (candidate_[cur] & 2) != 0;) {
      cur = indexOf(next_[cur]);
      put(cur, ++hi);
    }
    std::array<std::int16_t, stripe::kWindowTransitions> found{};
    int count = 0;
    for (int j = lo; j <= kChainEachWay && j + stripe::kWindowTransitions - 1 <= hi; ++j) {
      const unsigned window = (plus >> static_cast<unsigned>(j)) & kWindowMask;
      const unsigned first = (colours >> static_cast<unsigned>(2 * j)) & 3U;
      const int index = stripe::kWindowIndex[static_cast<std::size_t>(
          stripe::windowCode(static_cast<stripe::Colour>(first), static_cast<int>(window)))];
      if (index >= 0) {
        found[static_cast<std::size_t>(count++)] =
            static_cast<std::int16_t>(index + (kChainEachWay - j) + 1);
      }
    }
    vote(i, found, count);
  });
}

// Step 3. Union-find over touching boundary pixels of one class (parent = smaller index, path
// halving), then a weighted Boyer–Moore majority per root and a second pass for its support.
template <bool kReference>
void StripeDecoder::joinCurves() {
  const auto find = [this](std::int32_t i) {
    while (parent_[static_cast<std::size_t>(i)] != i) {
      const std::int32_t up =
          parent_[static_cast<std::size_t>(parent_[static_cast<std::size_t>(i)])];
      parent_[static_cast<std::size_t>(i)] = up;
      i = up;
    }
    return i;
  };
  const auto unite = [&](std::int32_t a, std::int32_t c) {
    const std::int32_t ra = find(a);
    const std::int32_t rc = find(c);
    if (ra < rc) {
      parent_[static_cast<std::size_t>(rc)] = ra;
    } else if (rc < ra) {
      parent_[static_cast<std::size_t>(ra)] = rc;
    }
  };
  eachBoundary<kReference>([&](std::size_t i) {
    parent_[i] = static_cast<std::int32_t>(i);
    weight_[i] = 0;
    total_[i] = 0;
    candidate_[i] = 0;
  });
  if (params_.curves) {
    // Locals, not the members: the int32 stores of unite() could alias them.
    const int width = width_;
    const int height = height_;
    const auto w = static_cast<std::size_t>(width);
    eachBoundary<kReference>([&](std::size_t at) {
      const int x = static_cast<int>(at % w);
      const int y = static_cast<int>(at / w);
      const auto i = static_cast<std::int32_t>(at);
      const std::uint8_t t = code_[at];
      if (x + 1 < width && code_[flat(x + 1, y, width)] == t) {
        unite(i, i + 1);
      }
      if (y + 1 == height) {
        return;
      }
      for (int dx = -1; dx <= 1; ++dx) {
        if (x + dx >= 0 && x + dx < width && code_[flat(x + dx, y + 1, width)] == t) {
          unite(i, i + width + dx);
        }
      }
    });
  }
  // The schedule flattens the forest once: a parent has the smaller index, so in ascending
  // order each parent already points at its root. Every later look-up is then one load.
  if constexpr (!kReference) {
    eachBoundary<false>(
        [&](std::size_t i) { parent_[i] = parent_[static_cast<std::size_t>(parent_[i])]; });
  }
  const auto rootOf = [&](std::size_t i) {
    return static_cast<std::size_t>(kReference ? find(static_cast<std::int32_t>(i)) : parent_[i]);
  };
  // Majority candidate per root, then its support among all votes of the curve.
  for (int pass = 0; pass < 2; ++pass) {
    eachBoundary<kReference>([&](std::size_t i) {
      const std::int32_t v = votes_[i];
      if (v == 0) {
        return;
      }
      const auto r = rootOf(i);
      if (pass == 0) {
        if (candidate_[r] == own_[i]) {
          weight_[r] += v;
        } else if (weight_[r] >= v) {
          weight_[r] -= v;
        } else {
          candidate_[r] = own_[i];
          weight_[r] = v - weight_[r];
        }
      } else {
        total_[r] += v;
        weight_[r] += candidate_[r] == own_[i] ? v : 0;
      }
    });
    if (pass == 0) {
      eachBoundary<kReference>([&](std::size_t i) { weight_[i] = 0; });
    }
  }
  std::fill(level_.begin(), level_.end(), std::int16_t{0});
  eachBoundary<kReference>([&](std::size_t i) {
    const auto r = rootOf(i);
    const bool majority = 2 * weight_[r] > total_[r] && weight_[r] >= params_.minCurveVotes;
    if (r == i && majority) {
      ++stats_.curves;
    }
    if (majority && (own_[i] == candidate_[r] || votes_[i] < 2)) {
      level_[i] = candidate_[r];
    }
  });
  // The next layer: a curve's links should lead to decoded curves one level on either side, at
  // about the same distance on both (a skipped or mislocated boundary makes one gap much longer
  // than the other). Per root, the links that fit (weight_) and the links to decoded pixels that
  // do not (total_); a curve with too large a share of misfits is dropped.
  eachBoundary<kReference>([&](std::size_t i) {
    weight_[i] = 0;
    total_[i] = 0;
  });
  const auto linkedLevel = [this](std::int32_t link) -> std::int32_t {
    return link == kNone ? 0 : level_[static_cast<std::size_t>(link)];
  };
  const std::int32_t ratio = params_.maxGapRatioPct;
  eachBoundary<kReference>([&](std::size_t i) {
    const std::int32_t level = level_[i];
    if (level == 0) {
      return;
    }
    const auto r = rootOf(i);
    const std::int32_t ahead = linkedLevel(next_[i]);
    const std::int32_t behind = linkedLevel(prev_[i]);
    bool aheadFits = ahead == level + 1;
    bool behindFits = behind == level - 1;
    // Level 1 has no boundary behind it (behind = 0 fits): no gap to compare. The gaps are the
    // links' distances along the axis (step 1); their products with ratio ≤ 400 fit in int32.
    if (aheadFits && behindFits && behind != 0 && ratio > 0) {
      aheadFits = 100 * std::int32_t{gapNext_[i]} <= ratio * gapPrev_[i];
      behindFits = 100 * std::int32_t{gapPrev_[i]} <= ratio * gapNext_[i];
    }
    weight_[r] += (aheadFits ? 1 : 0) + (behindFits ? 1 : 0);
    total_[r] += (ahead != 0 && !aheadFits ? 1 : 0) + (behind != 0 && !behindFits ? 1 : 0);
  });
  eachBoundary<kReference>([&](std::size_t i) {
    if (level_[i] == 0) {
      return;
    }
    const auto r = rootOf(i);
    if (std::int64_t{100} * total_[r] >
        std::int64_t{params_.maxNeighbourDisagreePct} * (total_[r] + weight_[r])) {
      level_[i] = 0;
    } else {
      ++stats_.decodedPixels;
    }
  });
}

// The schedule's step 3b for a pixel whose window lies inside the image, at the default radius:
// the same terms in the same order, the window's offsets constants.
template <int kRadius>
void StripeDecoder::sumLevelAround(std::size_t i, Unit u, std::int32_t& sum,
                                   std::int32_t& count) const {
  const std::int16_t level = level_[i];
  const auto w = static_cast<std::ptrdiff_t>(width_);
  for (int dy = -kRadius; dy <= kRadius; ++dy) {
    for (int dx = -kRadius; dx <= kRadius; ++dx) {
      const auto q = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(i) + dy * w + dx);
      if (level_[q] == level) {
        sum += along({0, 0}, {dx * 256 + shift_[q].x, dy * 256 + shift_[q].y}, u);
        ++count;
      }
    }
  }
}

// Step 3b. A decoded boundary's position along its axis becomes the mean over the pixels of the
// same level within positionRadiusPx (the boundary is locally a line across the axis, so they
// measure the same thing with independent noise). Means in Q8 (int32 sums of ≤ 81 terms), kept
// in weight_ (free after step 3) until all are computed, then written back as shifts.
template <bool kReference>
void StripeDecoder::smoothPositions(ConstDirectionPlane d) {
  const int r = params_.positionRadiusPx;
  if (r == 0) {
    return;
  }
  const demux::UnitTable& units = units_[0];
  const auto w = static_cast<std::size_t>(width_);
  eachBoundary<kReference>([&](std::size_t i) {
    const int x = static_cast<int>(i % w);
    const int y = static_cast<int>(i / w);
    const std::int16_t level = level_[i];
    if (level == 0) {
      return;
    }
    const Unit u = unitOf(units, d.rowPtr(y)[x]);
    const PointQ8 centre{x * 256, y * 256};
    std::int32_t sum = 0;
    std::int32_t count = 0;
    if (!kReference && r == kPositionRadius && x >= r && y >= r && x + r < width_ &&
        y + r < height_) {
      sumLevelAround<kPositionRadius>(i, u, sum, count);
      weight_[i] = (sum >= 0 ? sum + count / 2 : sum - count / 2) / count;
      return;
    }
    for (int qy = y > r ? y - r : 0; qy <= y + r && qy < height_; ++qy) {
      for (int qx = x > r ? x - r : 0; qx <= x + r && qx < width_; ++qx) {
        const std::size_t q = flat(qx, qy, width_);
        if (level_[q] == level) {
          sum += along(centre, {qx * 256 + shift_[q].x, qy * 256 + shift_[q].y}, u);
          ++count;
        }
      }
    }
    // count ≥ 1 (the pixel itself counts); round half away from zero.
    weight_[i] = count > 0 ? (sum >= 0 ? sum + count / 2 : sum - count / 2) / count : 0;
  });
  eachBoundary<kReference>([&](std::size_t i) {
    if (level_[i] == 0) {
      return;
    }
    const Unit u = unitOf(units, d.rowPtr(static_cast<int>(i / w))[i % w]);
    shift_[i] = {static_cast<std::int16_t>((weight_[i] * u.x + 8192) >> 14),
                 static_cast<std::int16_t>((weight_[i] * u.y + 8192) >> 14)};
  });
}

// Step 4. Every row, then every column, as a scan line; each pixel takes the kind of line nearer
// its own axis (a row when the axis lies within 45° of x), which a boundary curve crosses with a
// pixel on it (an 8-connected curve within 45° of the line's normal has a pixel on every line it
// spans). A curve missing its pixel on a line leaves that line's pixels beside it without a
// coordinate: filling them from the neighbouring line (as the walks of step 1 look at 2 × 2 blocks)
// gives more coordinates but more wrong ones (docs/decode.md).
void StripeDecoder::fill(ConstDirectionPlane d, StripePlane stripe) {
  int rowPixels = 0;
  // Locals, not the members: the byte stores below could alias them.
  const int w = width_;
  const int h = height_;
  for (int y = 0; y < h; ++y) {
    StripeQ16* out = stripe.rowPtr(y);
    const std::uint16_t* dirs = d.rowPtr(y);
    std::uint8_t* axis = &axis_[flat(0, y, w)];
    for (int x = 0; x < w; ++x) {
      out[x] = kNoStripe;
      // Within 45° of ±x: the angle (2^16 a turn) plus an eighth turn, modulo a half turn, lies
      // in the first quarter turn.
      const bool row = ((dirs[x] + 8192U) & 32767U) < 16384U;
      axis[x] = row ? kRowAxis : kColumnAxis;
      rowPixels += row ? 1 : 0;
    }
  }
  if (rowPixels > 0) {
    for (int y = 0; y < height_; ++y) {
      fillLine(d, stripe, kRowAxis, width_, [y](int t) { return PixelXY{t, y}; });
    }
  }
  if (rowPixels < width_ * height_) {
    for (int x = 0; x < width_; ++x) {
      fillLine(d, stripe, kColumnAxis, height_, [x](int t) { return PixelXY{x, t}; });
    }
  }
}

// One scan line of step 4: `length` pixels, pixel t at pixelAt(t). The line's boundary pixels,
// in order, form groups: runs of adjacent pixels of one class, one boundary crossing the line. A
// group's level is its decoded pixels' level (0 when they disagree or none is decoded), its
// position their mean position (all lie on the boundary). Between two consecutive groups whose
// levels are k and k + 1 (in either order) lie the pixels from the first group to the second;
// each of them whose axis takes this kind of line gets s = k + first / between along its own
// axis u: first = (pixel − q) · u, between = (n − q) · u, q and n the positions of the level-k and
// level-k + 1 groups, when 0 ≤ first < between ≤ maxGapPx + 1 px (a group's pixel lies between
// two pairs; the first that holds it wins). An undecoded boundary (level 0) or a missing one
// (levels k and k + 2) between two groups leaves the pixels there without a coordinate.
template <class PixelAt>
void StripeDecoder::fillLine(ConstDirectionPlane d, StripePlane stripe, std::uint8_t axis,
                             int length, PixelAt pixelAt) {
  const demux::UnitTable& units = units_[0];
  const auto indexAt = [&](int t) {
    const PixelXY p = pixelAt(t);
    return flat(p.x, p.y, width_);
  };
  int count = 0;
  for (int t = 0; t < length; ++t) {
    if (code_[indexAt(t)] != 0) {
      line_[static_cast<std::size_t>(count++)] = t;
    }
  }
  const auto at = [&](int j) { return line_[static_cast<std::size_t>(j)]; };
  struct Group {
    int first;  // pixels first … last of the line
    int last;
    std::int32_t level;
    PointQ8 position;
  };
  // The group of line_[start … end].
  const auto groupOf = [&](int start, int end) {
    Group g{at(start), at(end), 0, {0, 0}};
    PointQ8 sum{0, 0};
    int decoded = 0;
    for (int j = start; j <= end; ++j) {
      const PixelXY p = pixelAt(at(j));
      const std::size_t i = flat(p.x, p.y, width_);
      const std::int32_t level = level_[i];
      if (level == 0) {
        continue;
      }
      g.level = g.level == 0 || g.level == level ? level : -1;
      sum.x += p.x * 256 + shift_[i].x;
      sum.y += p.y * 256 + shift_[i].y;
      ++decoded;
    }
    if (g.level > 0) {
      g.position = {sum.x / decoded, sum.y / decoded};
    } else {
      g.level = 0;
    }
    return g;
  };
  const std::int32_t maxBetween = (params_.maxGapPx + 1) * 256;
  const auto fillBetween = [&](const Group& a, const Group& b) {
    if (a.level == 0 || b.level == 0 || (a.level - b.level != 1 && b.level - a.level != 1)) {
      return;
    }
    const Group& lower = a.level < b.level ? a : b;
    const Group& upper = a.level < b.level ? b : a;
    for (int t = a.first; t <= b.last; ++t) {
      const PixelXY p = pixelAt(t);
      StripeQ16& out = stripe.rowPtr(p.y)[p.x];
      if (axis_[flat(p.x, p.y, width_)] != axis || out != kNoStripe) {
        continue;
      }
      const Unit u = unitOf(units, d.rowPtr(p.y)[p.x]);
      const std::int32_t first = along(lower.position, {p.x * 256, p.y * 256}, u);
      const std::int32_t between = along(lower.position, upper.position, u);
      if (first < 0 || first >= between || between > maxBetween) {
        continue;
      }
      out = static_cast<StripeQ16>(std::int64_t{lower.level} * kStripeOne +
                                   std::int64_t{first} * kStripeOne / between);
      ++stats_.densePixels;
    }
  };
  Group previous{-1, -1, 0, {0, 0}};
  int start = 0;
  for (int j = 0; j < count; ++j) {
    if (j + 1 < count && at(j + 1) == at(j) + 1 &&
        code_[indexAt(at(j + 1))] == code_[indexAt(at(j))]) {
      continue;  // the group goes on
    }
    const Group g = groupOf(start, j);
    if (previous.first >= 0) {
      fillBetween(previous, g);
    }
    previous = g;
    start = j + 1;
  }
}

}  // namespace smx::algo
