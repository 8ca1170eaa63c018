#include "smx/eval/boundary_eval.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace smx::eval {
namespace {

using algo::ImageView;

constexpr double kTurn = 65536.0;
constexpr int kMaxCode = algo::stripe::kTransitions;  // valid transition codes are 1..6

template <class A, class B>
void requireSameSize(const ImageView<A>& a, const ImageView<B>& b, const char* what) {
  if (a.width() != b.width() || a.height() != b.height()) {
    throw std::invalid_argument(std::string("boundary_eval: ") + what + " " +
                                std::to_string(b.width()) + "x" + std::to_string(b.height()) +
                                " does not match " + std::to_string(a.width()) + "x" +
                                std::to_string(a.height()));
  }
}

bool inside(const ImageView<const float>& s, int x, int y) {
  return x >= 0 && y >= 0 && x < s.width() && y < s.height();
}

// s at (x, y) as double, NaN outside the image.
double sampleOrNan(const ImageView<const float>& s, int x, int y) {
  return inside(s, x, y) ? static_cast<double>(s(x, y)) : std::numeric_limits<double>::quiet_NaN();
}

// One axis of the gradient: central, else one-sided, else nullopt.
std::optional<double> axisDerivative(double before, double centre, double after) {
  const bool hasBefore = std::isfinite(before);
  const bool hasAfter = std::isfinite(after);
  if (hasBefore && hasAfter) {
    return (after - before) / 2.0;
  }
  if (hasAfter) {
    return after - centre;
  }
  if (hasBefore) {
    return centre - before;
  }
  return std::nullopt;
}

int roundHalfUp(double v) {
  return static_cast<int>(std::floor(v + 0.5));
}

algo::stripe::Transition trueTransition(int level) {
  const auto k = static_cast<std::size_t>(level);
  return algo::stripe::transitionBetween(algo::stripe::kSequence[k - 1],
                                         algo::stripe::kSequence[k]);
}

// s at the continuous position (px, py) by bilinear interpolation, when the 4 pixels around it
// are in the image and finite.
std::optional<double> bilinear(const ImageView<const float>& s, double px, double py) {
  const double fx = std::floor(px);
  const double fy = std::floor(py);
  if (fx < 0 || fy < 0 || fx + 1 >= s.width() || fy + 1 >= s.height()) {
    return std::nullopt;
  }
  const int x0 = static_cast<int>(fx);
  const int y0 = static_cast<int>(fy);
  const double s00 = s(x0, y0);
  const double s10 = s(x0 + 1, y0);
  const double s01 = s(x0, y0 + 1);
  const double s11 = s(x0 + 1, y0 + 1);
  if (!std::isfinite(s00) || !std::isfinite(s10) || !std::isfinite(s01) || !std::isfinite(s11)) {
    return std::nullopt;
  }
  const double tx = px - fx;
  const double ty = py - fy;
  return (s00 * (1 - tx) + s10 * tx) * (1 - ty) + (s01 * (1 - tx) + s11 * tx) * ty;
}

// Linear-interpolated percentile of sorted values, q in [0, 1].
double percentile(const std::vector<double>& sorted, double q) {
  const double pos = static_cast<double>(sorted.size() - 1) * q;
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  const double t = pos - static_cast<double>(lo);
  return sorted[lo] + (sorted[hi] - sorted[lo]) * t;
}

std::size_t indexOf(int width, int x, int y) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
         static_cast<std::size_t>(x);
}

Mask litCount(std::span<const ImageView<const std::uint8_t>> lits, int n, bool exactly) {
  if (lits.empty()) {
    return {};
  }
  for (const auto& lit : lits) {
    requireSameSize(lits.front(), lit, "lit plane");
  }
  Mask out = Mask::filled(lits.front().width(), lits.front().height(), 0);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      int count = 0;
      for (const auto& lit : lits) {
        count += lit(x, y) != 0 ? 1 : 0;
      }
      const bool keep = exactly ? count == n : count >= n;
      out.at(x, y) = keep ? 255 : 0;
    }
  }
  return out;
}

}  // namespace

Mask Mask::filled(int width, int height, std::uint8_t value) {
  if (width < 0 || height < 0) {
    throw std::invalid_argument("boundary_eval: negative mask size");
  }
  Mask m;
  m.width = width;
  m.height = height;
  m.pixels.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), value);
  return m;
}

ImageView<const std::uint8_t> Mask::view() const {
  return *ImageView<const std::uint8_t>::packed(pixels, width, height);
}

ImageView<std::uint8_t> Mask::mutableView() {
  return *ImageView<std::uint8_t>::packed(pixels, width, height);
}

std::uint8_t& Mask::at(int x, int y) {
  return pixels[indexOf(width, x, y)];
}

std::uint8_t Mask::at(int x, int y) const {
  return pixels[indexOf(width, x, y)];
}

int Mask::count() const {
  return static_cast<int>(
      std::count_if(pixels.begin(), pixels.end(), [](std::uint8_t v) { return v != 0; }));
}

std::optional<StripeGradient> stripeGradient(ImageView<const float> stripe, int x, int y) {
  if (!inside(stripe, x, y)) {
    return std::nullopt;
  }
  const double centre = stripe(x, y);
  if (!std::isfinite(centre)) {
    return std::nullopt;
  }
  const auto gx =
      axisDerivative(sampleOrNan(stripe, x - 1, y), centre, sampleOrNan(stripe, x + 1, y));
  const auto gy =
      axisDerivative(sampleOrNan(stripe, x, y - 1), centre, sampleOrNan(stripe, x, y + 1));
  if (!gx || !gy) {
    return std::nullopt;
  }
  const double magnitude = std::hypot(*gx, *gy);
  if (!(magnitude >= kMinStripesPerPx)) {
    return std::nullopt;
  }
  return StripeGradient{.gx = *gx, .gy = *gy, .magnitude = magnitude};
}

double medianStripeWidthPx(algo::ImageView<const float> stripe, int step) {
  std::vector<double> widths;
  for (int y = 0; y < stripe.height(); y += step) {
    for (int x = 0; x < stripe.width(); x += step) {
      if (const auto g = stripeGradient(stripe, x, y)) {
        widths.push_back(1.0 / g->magnitude);
      }
    }
  }
  if (widths.empty()) {
    return 0;
  }
  auto mid = widths.begin() + static_cast<std::ptrdiff_t>(widths.size() / 2);
  std::ranges::nth_element(widths, mid);
  return *mid;
}

std::optional<TrueBoundary> trueBoundaryAt(ImageView<const float> stripe, int x, int y) {
  const auto g = stripeGradient(stripe, x, y);
  if (!g) {
    return std::nullopt;
  }
  const double s = stripe(x, y);
  const int level = roundHalfUp(s);
  if (level < kFirstLevel || level > kLastLevel) {
    return std::nullopt;
  }
  const double delta = (level - s) / g->magnitude;
  if (delta < -0.5 || delta >= 0.5) {
    return std::nullopt;
  }
  return TrueBoundary{.level = level, .deltaPx = delta, .transition = trueTransition(level)};
}

double directionRadians(std::uint16_t raw) {
  return static_cast<double>(raw) * (2.0 * std::numbers::pi / kTurn);
}

std::uint16_t directionRaw(double radians) {
  const double turns = radians / (2.0 * std::numbers::pi);
  const double wrapped = turns - std::floor(turns);  // [0, 1]
  const auto raw = std::lround(wrapped * kTurn);
  return static_cast<std::uint16_t>(raw % 65536);
}

BoundaryScore scoreBoundaries(algo::ConstBoundaryPlane detected,
                              algo::ConstDirectionPlane direction, ImageView<const float> stripe,
                              ImageView<const std::uint8_t> region, const ScoreOptions& options) {
  requireSameSize(stripe, detected, "detected plane");
  requireSameSize(stripe, direction, "direction plane");
  requireSameSize(stripe, region, "region");
  const int w = stripe.width();
  const int h = stripe.height();

  // Owned level per pixel (0: none), independent of the region.
  std::vector<int> owned(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (const auto t = trueBoundaryAt(stripe, x, y)) {
        owned[indexOf(w, x, y)] = t->level;
      }
    }
  }
  const auto ownsInNeighbourhood = [&](int x, int y, int level) {
    for (int ny = std::max(0, y - 1); ny <= std::min(h - 1, y + 1); ++ny) {
      for (int nx = std::max(0, x - 1); nx <= std::min(w - 1, x + 1); ++nx) {
        if (owned[indexOf(w, nx, ny)] == level) {
          return true;
        }
      }
    }
    return false;
  };

  BoundaryScore score;
  std::vector<int> matchedLevel(owned.size(), 0);  // per detection pixel, 0: not matched
  double sumE = 0;
  double sumE2 = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const algo::Boundary b = detected(x, y);
      if (!b.present() || region(x, y) == 0) {
        continue;
      }
      ++score.detected;
      const bool validCode = b.transition <= kMaxCode;
      if (!validCode) {
        ++score.invalidTransitions;
      }
      const auto g = stripeGradient(stripe, x, y);
      if (!g) {
        ++score.detectedWithoutTruth;
        continue;
      }
      const double angle = directionRadians(direction(x, y));
      const double dx = std::cos(angle);
      const double dy = std::sin(angle);
      if (dx * g->gx + dy * g->gy < 0) {
        ++score.wrongDirectionSign;
      }
      const double along = b.offset / static_cast<double>(algo::Boundary::kOffsetOne);
      const double px = x + along * dx;
      const double py = y + along * dy;
      const double sDet =
          bilinear(stripe, px, py)
              .value_or(static_cast<double>(stripe(x, y)) + along * (g->gx * dx + g->gy * dy));
      const int level = roundHalfUp(sDet);
      const double e = (sDet - level) / g->magnitude;
      if (level < kFirstLevel || level > kLastLevel || !(std::abs(e) <= options.tolerancePx) ||
          !ownsInNeighbourhood(x, y, level)) {
        continue;
      }
      ++score.matched;
      matchedLevel[indexOf(w, x, y)] = level;
      if (owned[indexOf(w, x, y)] == level) {
        ++score.matchedAtOwner;
      }
      sumE += e;
      sumE2 += e * e;
      score.positionMaxAbsPx = std::max(score.positionMaxAbsPx, std::abs(e));
      if (validCode) {
        const auto truth = static_cast<std::size_t>(trueTransition(level));
        const auto kind = static_cast<std::size_t>(b.kind());
        ++score.confusion[truth][kind];
        if (truth == kind) {
          ++score.classCorrect;
        }
      }
    }
  }

  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int level = owned[indexOf(w, x, y)];
      if (level == 0 || region(x, y) == 0) {
        continue;
      }
      ++score.trueBoundaries;
      bool found = false;
      for (int ny = std::max(0, y - 1); ny <= std::min(h - 1, y + 1) && !found; ++ny) {
        for (int nx = std::max(0, x - 1); nx <= std::min(w - 1, x + 1) && !found; ++nx) {
          found = matchedLevel[indexOf(w, nx, ny)] == level;
        }
      }
      if (found) {
        ++score.recalled;
      }
    }
  }

  const auto ratio = [](int num, int den) {
    return den == 0 ? 1.0 : static_cast<double>(num) / static_cast<double>(den);
  };
  score.recall = ratio(score.recalled, score.trueBoundaries);
  score.precision = ratio(score.matched, score.detected);
  score.classAccuracy = ratio(score.classCorrect, score.matched);
  if (score.matched > 0) {
    score.positionMeanPx = sumE / score.matched;
    score.positionRmsPx = std::sqrt(sumE2 / score.matched);
  }
  return score;
}

AngleStats scoreDirections(algo::ConstDirectionPlane direction, ImageView<const float> stripe,
                           ImageView<const std::uint8_t> region) {
  requireSameSize(stripe, direction, "direction plane");
  requireSameSize(stripe, region, "region");
  std::vector<double> angles;
  int over90 = 0;
  for (int y = 0; y < stripe.height(); ++y) {
    for (int x = 0; x < stripe.width(); ++x) {
      if (region(x, y) == 0) {
        continue;
      }
      const auto g = stripeGradient(stripe, x, y);
      if (!g) {
        continue;
      }
      const double a = directionRadians(direction(x, y));
      const double dx = std::cos(a);
      const double dy = std::sin(a);
      const double cross = dx * g->uy() - dy * g->ux();
      const double dot = dx * g->ux() + dy * g->uy();
      const double deg = std::atan2(std::abs(cross), dot) * (180.0 / std::numbers::pi);
      angles.push_back(deg);
      if (deg > 90.0) {
        ++over90;
      }
    }
  }
  AngleStats stats;
  stats.count = static_cast<int>(angles.size());
  if (angles.empty()) {
    return stats;
  }
  std::sort(angles.begin(), angles.end());
  stats.medianDeg = percentile(angles, 0.5);
  stats.p95Deg = percentile(angles, 0.95);
  stats.maxDeg = angles.back();
  stats.fractionOver90 = static_cast<double>(over90) / static_cast<double>(angles.size());
  return stats;
}

Mask litByExactly(std::span<const ImageView<const std::uint8_t>> lits, int n) {
  return litCount(lits, n, true);
}

Mask litByAtLeast(std::span<const ImageView<const std::uint8_t>> lits, int n) {
  return litCount(lits, n, false);
}

Mask erode(const Mask& mask, int radiusPx) {
  if (radiusPx <= 0) {
    return mask;
  }
  const int r = radiusPx;
  Mask out = Mask::filled(mask.width, mask.height, 0);
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      if (mask.at(x, y) == 0) {
        continue;
      }
      bool keep = true;
      for (int dy = -r; dy <= r && keep; ++dy) {
        for (int dx = -r; dx <= r && keep; ++dx) {
          if (dx * dx + dy * dy > r * r) {
            continue;
          }
          const int nx = x + dx;
          const int ny = y + dy;
          keep = nx >= 0 && ny >= 0 && nx < mask.width && ny < mask.height && mask.at(nx, ny) != 0;
        }
      }
      out.at(x, y) = keep ? mask.at(x, y) : 0;
    }
  }
  return out;
}

Mask smoothOnly(const Mask& mask, ImageView<const float> depth, double maxRelativeJump) {
  requireSameSize(mask.view(), depth, "depth plane");
  Mask out = Mask::filled(mask.width, mask.height, 0);
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      if (mask.at(x, y) == 0) {
        continue;
      }
      const double centre = depth(x, y);
      bool keep = std::isfinite(centre);
      for (int ny = std::max(0, y - 1); ny <= std::min(mask.height - 1, y + 1) && keep; ++ny) {
        for (int nx = std::max(0, x - 1); nx <= std::min(mask.width - 1, x + 1) && keep; ++nx) {
          const double d = depth(nx, ny);
          keep = std::isfinite(d) && std::abs(d - centre) <= maxRelativeJump * std::abs(centre);
        }
      }
      out.at(x, y) = keep ? mask.at(x, y) : 0;
    }
  }
  return out;
}

}  // namespace smx::eval
