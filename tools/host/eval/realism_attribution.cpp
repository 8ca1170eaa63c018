#include "smx/eval/realism_attribution.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "smx/algo/lens.hpp"
#include "smx/eval/depth_eval.hpp"
#include "smx/eval/realism_eval.hpp"

namespace smx::eval {

namespace {

using algo::lens::Point3;

constexpr unsigned bit(Cause c) {
  return 1U << static_cast<unsigned>(c);
}

std::optional<Point3> cameraPoint(const SimFrame& f, int camera, int x, int y) {
  if (x < 0 || y < 0 || x >= f.depth.width || y >= f.depth.height) {
    return std::nullopt;
  }
  const double z = f.depth.at(x, y);
  if (!std::isfinite(z)) {
    return std::nullopt;
  }
  return algo::lens::devicePoint(f.rig.cameras.at(static_cast<std::size_t>(camera)),
                                 {static_cast<double>(x), static_cast<double>(y)}, z);
}

Point3 minus(const Point3& a, const Point3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

// |cos| of the angle between two vectors; the normal's orientation does not matter.
double absCos(const Point3& a, const Point3& b) {
  const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  return std::abs(dot) / (std::hypot(a[0], a[1], a[2]) * std::hypot(b[0], b[1], b[2]));
}

bool narrow(const SimFrame& f, int x, int y) {
  for (std::size_t p = 0; p < f.lit.size(); ++p) {
    if (f.lit[p].at(x, y) == 0) {
      continue;
    }
    const auto g = stripeGradient(f.stripe[p].view(), x, y);
    if (!g || 1.0 / g->magnitude < kNarrowStripePx) {
      return true;
    }
  }
  return false;
}

std::array<int, 3> boxSum(const SimFrame& f, int x, int y) {
  std::array<int, 3> sum{};
  for (int yy = y - 1; yy <= y + 1; ++yy) {
    for (int xx = x - 1; xx <= x + 1; ++xx) {
      const auto& px = f.image.at(xx, yy);
      sum[0] += px.r;
      sum[1] += px.g;
      sum[2] += px.b;
    }
  }
  return sum;
}

bool dim(const SimFrame& f, int x, int y) {
  const int r = kDimWindowRadiusPx;
  std::array<int, 3> lo{};
  std::array<int, 3> hi{};
  bool any = false;
  for (int yy = std::max(1, y - r); yy <= std::min(f.image.height - 2, y + r); ++yy) {
    for (int xx = std::max(1, x - r); xx <= std::min(f.image.width - 2, x + r); ++xx) {
      const auto sum = boxSum(f, xx, yy);
      for (std::size_t i = 0; i < 3; ++i) {
        lo[i] = any ? std::min(lo[i], sum[i]) : sum[i];
        hi[i] = any ? std::max(hi[i], sum[i]) : sum[i];
      }
      any = true;
    }
  }
  // Sums of 9 pixels: compare against 9 × the threshold to stay in integers.
  return std::ranges::none_of(std::array{0, 1, 2}, [&](int i) {
    const auto c = static_cast<std::size_t>(i);
    return hi[c] - lo[c] >= 9 * kDimContrastDn;
  });
}

bool grazing(const SimFrame& f, int camera, int x, int y) {
  const auto p = cameraPoint(f, camera, x, y);
  const auto left = cameraPoint(f, camera, x - 1, y);
  const auto right = cameraPoint(f, camera, x + 1, y);
  const auto up = cameraPoint(f, camera, x, y - 1);
  const auto down = cameraPoint(f, camera, x, y + 1);
  if (!p || !left || !right || !up || !down) {
    return false;
  }
  const Point3 dx = minus(*right, *left);
  const Point3 dy = minus(*down, *up);
  const Point3 n{dx[1] * dy[2] - dx[2] * dy[1], dx[2] * dy[0] - dx[0] * dy[2],
                 dx[0] * dy[1] - dx[1] * dy[0]};
  const double cosLimit = std::cos(kGrazingDeg * std::numbers::pi / 180.0);
  if (absCos(n, *p) < cosLimit) {
    return true;
  }
  const auto& cam = f.rig.cameras.at(static_cast<std::size_t>(camera));
  bool anyLit = false;
  for (std::size_t j = 0; j < f.lit.size(); ++j) {
    if (f.lit[j].at(x, y) == 0) {
      continue;
    }
    anyLit = true;
    const Point3 c = algo::lens::toDevice(cam, algo::lens::centre(f.rig.projectors.at(j)));
    if (absCos(n, minus(*p, c)) >= cosLimit) {
      return false;
    }
  }
  return anyLit;
}

void count(CauseTally& t, bool valid, bool gross) {
  ++t.region;
  t.valid += valid ? 1 : 0;
  t.gross += gross ? 1 : 0;
}

void add(CauseTally& a, const CauseTally& b) {
  a.region += b.region;
  a.valid += b.valid;
  a.gross += b.gross;
}

double ratio(int num, int den) {
  return den > 0 ? static_cast<double>(num) / den : 0.0;
}

CauseTally total(const std::array<CauseTally, kCauses>& byCause) {
  CauseTally t;
  for (const auto& c : byCause) {
    add(t, c);
  }
  return t;
}

// The tally left after removing the pixels meeting condition c (kOther: any named one).
CauseTally remaining(const std::array<CauseTally, kCauses>& byCause,
                     const std::array<CauseTally, kNamedCauses>& with, std::optional<Cause> c) {
  CauseTally t = total(byCause);
  if (!c) {
    return t;
  }
  if (*c == Cause::kOther) {
    return byCause[static_cast<std::size_t>(Cause::kOther)];
  }
  const auto& w = with[static_cast<std::size_t>(*c)];
  t.region -= w.region;
  t.valid -= w.valid;
  t.gross -= w.gross;
  return t;
}

}  // namespace

const char* causeName(Cause c) {
  switch (c) {
    case Cause::kNarrow:
      return "narrow";
    case Cause::kSingle:
      return "single";
    case Cause::kDim:
      return "dim";
    case Cause::kGrazing:
      return "grazing";
    case Cause::kEdge:
      return "edge";
    case Cause::kTriple:
      return "triple";
    case Cause::kOther:
      return "other";
  }
  return "other";
}

unsigned pixelConditions(const SimFrame& frame, int camera, const Mask& nearEdge, int x, int y) {
  unsigned bits = 0;
  if (narrow(frame, x, y)) {
    bits |= bit(Cause::kNarrow);
  }
  const auto lighting = std::ranges::count_if(
      frame.lit, [&](const OwnedPlane<std::uint8_t>& l) { return l.at(x, y) != 0; });
  if (lighting == 1) {
    bits |= bit(Cause::kSingle);
  }
  if (dim(frame, x, y)) {
    bits |= bit(Cause::kDim);
  }
  if (grazing(frame, camera, x, y)) {
    bits |= bit(Cause::kGrazing);
  }
  if (nearEdge.at(x, y) != 0) {
    bits |= bit(Cause::kEdge);
  }
  if (lighting == 3) {
    bits |= bit(Cause::kTriple);
  }
  return bits;
}

Cause firstCause(unsigned conditions) {
  for (int c = 0; c < kNamedCauses; ++c) {
    if ((conditions & (1U << static_cast<unsigned>(c))) != 0) {
      return static_cast<Cause>(c);
    }
  }
  return Cause::kOther;
}

Attribution attributeRun(const SimFrame& frame, int camera, algo::ConstDepthPlane merged,
                         const Mask& outsideBand, const Mask& resolvable, double depthUnitM) {
  Attribution a;
  const Mask nearEdge = discontinuityBand(frame.depth.view(), kNearEdgePx);
  for (int y = 0; y < merged.height(); ++y) {
    for (int x = 0; x < merged.width(); ++x) {
      const bool inBand = outsideBand.at(x, y) != 0;
      const bool inResolvable = resolvable.at(x, y) != 0;
      const double truth = frame.depth.at(x, y);
      if ((!inBand && !inResolvable) || !std::isfinite(truth)) {
        continue;
      }
      const unsigned bits = pixelConditions(frame, camera, nearEdge, x, y);
      const auto first = static_cast<std::size_t>(firstCause(bits));
      const bool valid = merged(x, y) != 0;
      const bool gross = valid && isGrossError(merged(x, y) * depthUnitM, truth);
      if (inBand) {
        count(a.outsideBand[first], valid, gross);
      }
      if (inResolvable) {
        count(a.resolvable[first], valid, gross);
      }
      for (std::size_t c = 0; c < kNamedCauses; ++c) {
        if ((bits & (1U << c)) == 0) {
          continue;
        }
        if (inBand) {
          count(a.outsideBandWith[c], valid, gross);
        }
        if (inResolvable) {
          count(a.resolvableWith[c], valid, gross);
        }
      }
    }
  }
  return a;
}

Attribution sumAttributions(std::span<const Attribution> runs) {
  Attribution t;
  for (const auto& r : runs) {
    for (std::size_t c = 0; c < kCauses; ++c) {
      add(t.outsideBand[c], r.outsideBand[c]);
      add(t.resolvable[c], r.resolvable[c]);
    }
    for (std::size_t c = 0; c < kNamedCauses; ++c) {
      add(t.outsideBandWith[c], r.outsideBandWith[c]);
      add(t.resolvableWith[c], r.resolvableWith[c]);
    }
  }
  return t;
}

double grossShare(const Attribution& a, Cause c) {
  return ratio(a.outsideBand[static_cast<std::size_t>(c)].gross, total(a.outsideBand).gross);
}

double missingShare(const Attribution& a, Cause c) {
  return ratio(a.resolvable[static_cast<std::size_t>(c)].missing(), total(a.resolvable).missing());
}

double grossRateWithout(const Attribution& a, std::optional<Cause> c) {
  const CauseTally t = remaining(a.outsideBand, a.outsideBandWith, c);
  return ratio(t.gross, t.valid);
}

double completenessWithout(const Attribution& a, std::optional<Cause> c) {
  const CauseTally t = remaining(a.resolvable, a.resolvableWith, c);
  return ratio(t.valid, t.region);
}

}  // namespace smx::eval
