#include "smx/algo/pattern_image.hpp"

#include <cmath>
#include <numbers>

namespace smx::algo {

double stripeCoordinate(const StripePattern& pattern, int projectorWidth, int projectorHeight,
                        double u, double v) {
  const double a = pattern.angleDeg * std::numbers::pi / 180.0;
  const double cu = (projectorWidth - 1) / 2.0;
  const double cv = (projectorHeight - 1) / 2.0;
  const double alongAxis = (u - cu) * std::cos(a) + (v - cv) * std::sin(a);
  return (alongAxis - pattern.offsetPx) / pattern.stripePx + stripe::kStripes / 2.0;
}

int visibleStripes(const Projector& p) {
  const double a = p.pattern.angleDeg * std::numbers::pi / 180.0;
  int visible = 0;
  for (int i = 0; i < stripe::kStripes; ++i) {
    bool inside = true;
    for (const double edge : {static_cast<double>(i), i + 1.0}) {
      const double along =
          p.pattern.offsetPx + (edge - stripe::kStripes / 2.0) * p.pattern.stripePx;
      const double u = (p.width - 1) / 2.0 + along * std::cos(a);
      const double v = (p.height - 1) / 2.0 + along * std::sin(a);
      inside = inside && u >= -0.5 && v >= -0.5 && u <= p.width - 0.5 && v <= p.height - 0.5;
    }
    visible += inside ? 1 : 0;
  }
  return visible;
}

Result<void> renderPatternImage(const Projector& projector, RgbView out) {
  if (out.width() != projector.width || out.height() != projector.height) {
    return fail(Errc::kSizeMismatch, "pattern image size differs from the projector's");
  }
  if (!(projector.pattern.stripePx > 0.0)) {
    return fail(Errc::kInvalidArgument, "stripe width must be positive");
  }
  // s(u, v) is affine: s = s(0, 0) + u·du + v·dv.
  const auto& pattern = projector.pattern;
  const double s00 = stripeCoordinate(pattern, projector.width, projector.height, 0.0, 0.0);
  const double du = stripeCoordinate(pattern, projector.width, projector.height, 1.0, 0.0) - s00;
  const double dv = stripeCoordinate(pattern, projector.width, projector.height, 0.0, 1.0) - s00;
  for (int v = 0; v < out.height(); ++v) {
    const auto row = out.row(v);
    for (int u = 0; u < out.width(); ++u) {
      const double s = std::floor(s00 + u * du + v * dv);
      row[static_cast<std::size_t>(u)] =
          (s >= 0.0 && s < stripe::kStripes)
              ? stripeRgb(stripe::kSequence[static_cast<std::size_t>(s)])
              : Rgb8{0, 0, 0};
    }
  }
  return {};
}

}  // namespace smx::algo
