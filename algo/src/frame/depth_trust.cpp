// Per-pair trust: resolvability and predicted depth error from the stripe gradient
// (depth_trust.hpp). This scalar code is the reference; its schedule, with the triangulation in
// the same pass, is triangulateTrusted() (depth_trust_schedule.cpp).
#include "smx/algo/depth_trust.hpp"

#include <cstdint>

#include "trust/trust_shared.hpp"

namespace smx::algo {

namespace {

constexpr std::int64_t kOneOverPxQ24 = std::int64_t{1} << 24;  // 1 stripe/px in Q16 × width Q8

// The derivative of s along one axis from the pixel's value c and its neighbours before (a) and
// after (b); false when neither neighbour has a coordinate.
bool axisDerivative(StripeQ16 a, StripeQ16 c, StripeQ16 b, std::int64_t& d) {
  const bool hasA = a >= 0;
  const bool hasB = b >= 0;
  if (hasA && hasB) {
    d = (std::int64_t{b} - a) / 2;
  } else if (hasB) {
    d = std::int64_t{b} - c;
  } else if (hasA) {
    d = std::int64_t{c} - a;
  } else {
    return false;
  }
  d = d < 0 ? -d : d;
  return true;
}

}  // namespace

Result<void> validateDepthTrust(const DepthTrustParams& p) {
  if (p.boundaryErrorQ8 < 0 || p.boundaryErrorQ8 > 256) {
    return fail(Errc::kInvalidArgument, "trust: boundaryErrorQ8 must be 0 to 256");
  }
  if (p.minStripeWidthQ8 < 0 || p.minStripeWidthQ8 > 4096) {
    return fail(Errc::kInvalidArgument, "trust: minStripeWidthQ8 must be 0 to 4096");
  }
  if (p.errorMargin < 1 || p.errorMargin > 10) {
    return fail(Errc::kInvalidArgument, "trust: errorMargin must be 1 to 10");
  }
  if (p.tolerance.minUnits < 1 || p.tolerance.minUnits > 65535) {
    return fail(Errc::kInvalidArgument, "trust: tolerance.minUnits must be 1 to 65535");
  }
  if (p.tolerance.permille < 0 || p.tolerance.permille > 1000) {
    return fail(Errc::kInvalidArgument, "trust: tolerance.permille must be 0 to 1000");
  }
  if (p.nearUnits < 1 || p.farUnits < p.nearUnits || p.farUnits > 65535) {
    return fail(Errc::kInvalidArgument,
                "trust: the working range needs 1 <= nearUnits <= farUnits <= 65535");
  }
  return {};
}

Result<void> checkTrustArguments(const Triangulator& triangulator, ConstStripePlane stripe,
                                 DepthPlane depth, ImageView<std::uint8_t> confidence,
                                 const DepthTrustParams& params) {
  const int w = triangulator.width();
  const int h = triangulator.height();
  if (stripe.width() != w || stripe.height() != h || depth.width() != w || depth.height() != h ||
      confidence.width() != w || confidence.height() != h) {
    return fail(Errc::kSizeMismatch, "trust: planes must match the triangulation tables");
  }
  return validateDepthTrust(params);
}

Result<void> trustDepth(const Triangulator& triangulator, ConstStripePlane stripe, DepthPlane depth,
                        ImageView<std::uint8_t> confidence, const DepthTrustParams& params) {
  if (auto ok = checkTrustArguments(triangulator, stripe, depth, confidence, params); !ok) {
    return ok;
  }
  const int w = triangulator.width();
  const int h = triangulator.height();
  for (int y = 0; y < h; ++y) {
    const StripeQ16* row = stripe.rowPtr(y);
    const StripeQ16* up = y > 0 ? stripe.rowPtr(y - 1) : nullptr;
    const StripeQ16* down = y + 1 < h ? stripe.rowPtr(y + 1) : nullptr;
    std::uint16_t* z = depth.rowPtr(y);
    std::uint8_t* c = confidence.rowPtr(y);
    for (int x = 0; x < w; ++x) {
      c[x] = 0;
      const StripeQ16 s = row[x];
      if (z[x] == kNoDepth || s < 0) {
        z[x] = kNoDepth;
        continue;
      }
      std::int64_t dx = 0;
      std::int64_t dy = 0;
      const bool ok = axisDerivative(x > 0 ? row[x - 1] : kNoStripe, s,
                                     x + 1 < w ? row[x + 1] : kNoStripe, dx) &&
                      axisDerivative(up != nullptr ? up[x] : kNoStripe, s,
                                     down != nullptr ? down[x] : kNoStripe, dy);
      const std::int64_t hi = dx > dy ? dx : dy;
      const std::int64_t lo = dx > dy ? dy : dx;
      const std::int64_t blend = hi - hi / 8 + lo / 2;
      const std::int64_t gradient = blend > hi ? blend : hi;  // |∇s|, Q16 stripes per px
      if (!ok || gradient * params.minStripeWidthQ8 > kOneOverPxQ24) {
        z[x] = kNoDepth;
        continue;
      }
      // One-sided: z(s) is the pixel's depth already, and the second triangulation of the
      // central difference would cost as much again for a second-order difference.
      const std::int64_t ahead = s + ((gradient * params.boundaryErrorQ8 + 128) >> 8);
      const std::uint16_t zAhead = ahead < Triangulator::kMaxStripe
                                       ? triangulator.depthAt(x, y, static_cast<StripeQ16>(ahead))
                                       : kNoDepth;
      if (zAhead == kNoDepth) {
        z[x] = kNoDepth;
        continue;
      }
      const std::int64_t spread = std::int64_t{2} * (zAhead > z[x] ? zAhead - z[x] : z[x] - zAhead);
      c[x] = confidenceOf(spread, z[x], params);
      if (c[x] == 0) {
        z[x] = kNoDepth;
      }
    }
  }
  return {};
}

}  // namespace smx::algo
