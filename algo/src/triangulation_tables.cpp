// Init time: the triangulation tables of one projector–camera pair (triangulation.hpp), in
// double, then scaled to integers.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "smx/algo/lens.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/algo/triangulation.hpp"

namespace smx::algo {

namespace {

using Mat3 = std::array<double, 9>;
using Vec3 = std::array<double, 3>;

Vec3 mul(const Mat3& m, const Vec3& v) {
  return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
          m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}

double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// a · bᵀ for rotations: (R_p · R_cᵀ).
Mat3 mulTransposed(const Mat3& a, const Mat3& b) {
  Mat3 out{};
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c) {
      double v = 0;
      for (std::size_t k = 0; k < 3; ++k) {
        v += a[r * 3 + k] * b[c * 3 + k];
      }
      out[r * 3 + c] = v;
    }
  }
  return out;
}

// Camera → projector: X_p = M·X_c + m.
struct PairGeometry {
  Mat3 m3;
  Vec3 m;
};

// Exact stripe coordinate s_d(z) seen along one camera ray through the distorted projector.
class RaySampler {
 public:
  RaySampler(const Projector& proj, const PairGeometry& g, const Vec3& mr)
      : proj_(proj), g_(g), mr_(mr) {}

  struct Seen {
    bool defined = false;  // in front of the projector
    double s = 0.0;
    bool lit = false;  // inside the projector image and the stripe sequence
  };

  [[nodiscard]] Seen at(double z) const {
    const Vec3 xp{z * mr_[0] + g_.m[0], z * mr_[1] + g_.m[1], z * mr_[2] + g_.m[2]};
    if (!(xp[2] > 0.0)) {
      return {};
    }
    const lens::Point2 xd = lens::distort(proj_.dist, {xp[0] / xp[2], xp[1] / xp[2]});
    const double u = proj_.fx() * xd.x + proj_.cx();
    const double v = proj_.fy() * xd.y + proj_.cy();
    const double s = stripeCoordinate(proj_.pattern, proj_.width, proj_.height, u, v);
    const bool inImage =
        u >= -0.5 && v >= -0.5 && u <= proj_.width - 0.5 && v <= proj_.height - 0.5;
    return {true, s, inImage && s >= 0.0 && s < stripe::kStripes};
  }

 private:
  const Projector& proj_;
  const PairGeometry& g_;
  Vec3 mr_;
};

// Coefficients of z = (A + B·s + E·s² + F·s³) / (C + D·s), in that order: A, B, E, F, C, D.
using Fit = std::array<double, 6>;
constexpr std::size_t kFitNodes = 5;

// The fit through kFitNodes points (s_k, z_k). Solved in t = s − s̄ (stripes, centred) with the
// denominator 1 + D·t, which is 1 at s̄ (z is finite inside the range), then expanded in s.
// nullopt when the points do not determine it.
std::optional<Fit> fitThrough(const std::array<double, kFitNodes>& s,
                              const std::array<double, kFitNodes>& z) {
  double centre = 0.0;
  for (const double v : s) {
    centre += v / kFitNodes;
  }
  // Rows A + B·t + E·t² + F·t³ − D·t·z = z, Gauss–Jordan with partial pivoting.
  std::array<std::array<double, kFitNodes + 1>, kFitNodes> m{};
  for (std::size_t k = 0; k < kFitNodes; ++k) {
    const double t = s[k] - centre;
    m[k] = {1.0, t, t * t, t * t * t, -t * z[k], z[k]};
  }
  for (std::size_t c = 0; c < kFitNodes; ++c) {
    std::size_t pivot = c;
    for (std::size_t r = c + 1; r < kFitNodes; ++r) {
      pivot = std::abs(m[r][c]) > std::abs(m[pivot][c]) ? r : pivot;
    }
    std::swap(m[c], m[pivot]);
    if (!(std::abs(m[c][c]) > 1e-12)) {
      return std::nullopt;
    }
    for (std::size_t r = 0; r < kFitNodes; ++r) {
      if (r != c) {
        const double f = m[r][c] / m[c][c];
        for (std::size_t j = c; j <= kFitNodes; ++j) {
          m[r][j] -= f * m[c][j];
        }
      }
    }
  }
  std::array<double, kFitNodes> x{};
  for (std::size_t k = 0; k < kFitNodes; ++k) {
    x[k] = m[k][kFitNodes] / m[k][k];
  }
  const auto [a, b, e, f, d] = x;
  const double c = centre;
  return Fit{a - b * c + e * c * c - f * c * c * c,
             b - 2.0 * e * c + 3.0 * f * c * c,
             e - 3.0 * f * c,
             f,
             1.0 - d * c,
             d};
}

double denominatorOf(const Fit& f, double s) {
  return f[4] + f[5] * s;
}

double depthOf(const Fit& f, double s) {
  return (f[0] + s * (f[1] + s * (f[2] + s * f[3]))) / denominatorOf(f, s);
}

}  // namespace

double baselineM(const Rig& rig, int camera, int projector) {
  const lens::Point3 c = lens::centre(rig.cameras.at(static_cast<std::size_t>(camera)));
  const lens::Point3 p = lens::centre(rig.projectors.at(static_cast<std::size_t>(projector)));
  return std::hypot(c[0] - p[0], c[1] - p[1], c[2] - p[2]);
}

namespace {

std::string formatted(const char* format, double value) {
  std::array<char, 32> text{};
  (void)std::snprintf(text.data(), text.size(), format, value);
  return text.data();
}

// Each fitted pixel's own 2^k scaling of A, B, E, F, C, D (num and den scale alike; max(|C|, |D|)
// = 1): C', D' ≤ 2^30 and the numerator within 2^62 for any s in [0, 198) (triangulation.hpp).
void scaleFitted(const std::vector<Fit>& fit, double depthUnitM, TriangulationTables& t) {
  const double sMax = 198.0;
  const std::size_t pixels = fit.size();
  t.numerators.resize(pixels);
  t.denominatorBase.assign(pixels, 0);
  t.denominatorSlope.assign(pixels, 0);
  for (std::size_t i = 0; i < pixels; ++i) {
    if (t.sense[i] == 0) {
      continue;
    }
    const Fit& f = fit[i];
    const double bound = (std::abs(f[0]) + std::abs(f[1]) * sMax + std::abs(f[2]) * sMax * sMax +
                          std::abs(f[3]) * sMax * sMax * sMax) *
                         kStripeOne / depthUnitM;
    int k = 30;
    while (std::ldexp(bound, k) >= std::ldexp(1.0, 62)) {
      --k;
    }
    const auto scaled = [&](double v) { return std::ldexp(v, k) / depthUnitM; };
    t.numerators[i] = {std::llround(scaled(f[0]) * kStripeOne), std::llround(scaled(f[1])),
                       std::llround(scaled(f[2])), std::llround(scaled(f[3]))};
    t.denominatorBase[i] = static_cast<std::int32_t>(std::lround(std::ldexp(f[4], k)));
    t.denominatorSlope[i] = static_cast<std::int32_t>(std::lround(std::ldexp(f[5], k)));
  }
}

// The working range's depths: the fit's Chebyshev nodes and the check's samples, even in 1/z.
constexpr int kSamples = 17;
struct RangeDepths {
  std::array<double, kFitNodes> nodes{};
  std::array<double, kSamples> samples{};
  double nominal = 0.0;
};

RangeDepths rangeDepths(double nominalM) {
  const double wNear = 1.0 / (kFitNearFactor * nominalM);
  const double wFar = 1.0 / (kWorkingRangeFactor * nominalM);
  RangeDepths r;
  for (std::size_t k = 0; k < kFitNodes; ++k) {
    const double cosine = std::cos((2.0 * static_cast<double>(k) + 1.0) * std::numbers::pi /
                                   (2.0 * static_cast<double>(kFitNodes)));
    r.nodes[k] = 1.0 / ((wNear + wFar) / 2.0 + cosine * (wNear - wFar) / 2.0);
  }
  for (std::size_t j = 0; j < r.samples.size(); ++j) {
    r.samples[j] = 1.0 / (wNear - (wNear - wFar) * static_cast<double>(j) / (kSamples - 1));
  }
  r.nominal = nominalM;
  return r;
}

struct PixelFit {
  bool usable = false;
  Fit fit{};
  double rangeResidualM = 0.0;
  double nominalMissM = 0.0;
  bool litAtNominal = false;
};

// One pixel's fit, scaled so that max(|C|, |D|) = 1, and its check: every sample defined, s
// strictly monotone in z, the denominator positive (as it is at the nodes' centre); the residual
// over the lit samples and at the nominal depth.
PixelFit fitPixel(const RaySampler& ray, const RangeDepths& depths) {
  std::array<double, kFitNodes> nodeS{};
  for (std::size_t k = 0; k < kFitNodes; ++k) {
    const RaySampler::Seen seen = ray.at(depths.nodes[k]);
    if (!seen.defined) {
      return {};
    }
    nodeS[k] = seen.s;
  }
  const std::optional<Fit> solved = fitThrough(nodeS, depths.nodes);
  if (!solved) {
    return {};
  }
  PixelFit p;
  p.fit = *solved;
  const double scale = std::max(std::abs(p.fit[4]), std::abs(p.fit[5]));
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    return {};
  }
  for (double& v : p.fit) {
    v /= scale;
  }
  double previous = 0.0;
  double direction = 0.0;
  for (std::size_t j = 0; j < depths.samples.size(); ++j) {
    const RaySampler::Seen seen = ray.at(depths.samples[j]);
    if (!seen.defined || !(denominatorOf(p.fit, seen.s) > 0.0)) {
      return {};
    }
    if (j > 0) {
      const double step = seen.s - previous;
      if (step == 0.0 || (direction != 0.0 && (step > 0.0) != (direction > 0.0))) {
        return {};
      }
      direction = step;
    }
    previous = seen.s;
    if (seen.lit) {
      p.rangeResidualM =
          std::max(p.rangeResidualM, std::abs(depthOf(p.fit, seen.s) - depths.samples[j]));
    }
  }
  const RaySampler::Seen atNominal = ray.at(depths.nominal);
  if (atNominal.defined && atNominal.lit) {
    p.litAtNominal = true;
    p.nominalMissM = std::abs(depthOf(p.fit, atNominal.s) - depths.nominal);
  }
  p.usable = true;
  return p;
}

// A distorted projector: per pixel z = (A + B·s + E·s² + F·s³) / (C + D·s) exact at kFitNodes
// depths (Chebyshev nodes in 1/z over the working range), checked against exact s_d(z) at
// kSamples depths and at the nominal depth.
std::expected<TriangulationTables, std::string> fittedTables(const Camera& cam,
                                                             const Projector& proj,
                                                             const PairGeometry& g,
                                                             double depthUnitM, double nominalM) {
  const RangeDepths depths = rangeDepths(nominalM);
  const auto pixels = static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height);
  TriangulationTables t;
  t.width = cam.width;
  t.height = cam.height;
  t.sense.assign(pixels, 0);
  std::vector<Fit> fit(pixels, Fit{});
  std::int64_t lit = 0;     // pixels whose point at the nominal depth the projector lights
  std::int64_t missed = 0;  // of those, where the fit misses kMaxFitResidualM: no depth
  double worstMiss = 0.0;
  int worstX = 0;
  int worstY = 0;
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const lens::Point2 n =
          lens::undistort(cam.dist, {(x - cam.cx()) / cam.fx(), (y - cam.cy()) / cam.fy()})
              .value_or(lens::Point2{std::nan(""), std::nan("")});
      if (!std::isfinite(n.x)) {
        continue;
      }
      const PixelFit p = fitPixel(RaySampler(proj, g, mul(g.m3, {n.x, n.y, 1.0})), depths);
      if (!p.usable) {
        continue;
      }
      lit += p.litAtNominal ? 1 : 0;
      if (p.nominalMissM > kMaxFitResidualM) {
        // No depth rather than a depth the fit cannot promise (often a pixel whose stripes run
        // nearly along its epipolar line, where any stripe error is magnified).
        ++missed;
        if (p.nominalMissM > worstMiss) {
          worstMiss = p.nominalMissM;
          worstX = x;
          worstY = y;
        }
        continue;
      }
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(cam.width) +
                            static_cast<std::size_t>(x);
      fit[i] = p.fit;
      t.sense[i] = 1;
      t.rangeResidualM = std::max(t.rangeResidualM, p.rangeResidualM);
      t.nominalResidualM = std::max(t.nominalResidualM, p.nominalMissM);
    }
  }
  if (std::none_of(t.sense.begin(), t.sense.end(), [](std::int8_t v) { return v != 0; })) {
    return std::unexpected("projector '" + proj.id + "': no ray of camera '" + cam.id +
                           "' sees its stripes monotonically over the working range");
  }
  if (missed > static_cast<std::int64_t>(kMaxFitMissedShare * static_cast<double>(lit))) {
    return std::unexpected(
        "projector '" + proj.id + "': its lens distortion bends the stripes too much to " +
        "triangulate exact stripe coordinates within " +
        formatted("%.1f", kMaxFitResidualM * 1000.0) + " mm on " +
        formatted("%.1f", 100.0 * static_cast<double>(missed) / static_cast<double>(lit)) +
        " % of the pixels it lights at the nominal depth " + formatted("%g", nominalM) +
        " m (the fit misses by up to " + formatted("%.3f", worstMiss * 1000.0) + " mm, camera '" +
        cam.id + "' pixel " + std::to_string(worstX) + "," + std::to_string(worstY) +
        "; docs/triangulation.md)");
  }
  scaleFitted(fit, depthUnitM, t);
  return t;
}

}  // namespace

std::expected<TriangulationTables, std::string> buildTriangulationTables(
    const Rig& rig, int camera, int projector, double depthUnitM,
    std::optional<double> nominalDepthM) {
  if (camera < 0 || camera >= static_cast<int>(rig.cameras.size())) {
    return std::unexpected("triangulation: no camera " + std::to_string(camera) + " in the rig");
  }
  if (projector < 0 || projector >= static_cast<int>(rig.projectors.size())) {
    return std::unexpected("triangulation: no projector " + std::to_string(projector) +
                           " in the rig");
  }
  if (!(depthUnitM > 0.0) || !std::isfinite(depthUnitM)) {
    return std::unexpected("triangulation: the depth unit must be positive");
  }
  if (nominalDepthM && (!(*nominalDepthM > 0.0) || !std::isfinite(*nominalDepthM))) {
    return std::unexpected("triangulation: the nominal depth must be positive");
  }
  const Camera& cam = rig.cameras[static_cast<std::size_t>(camera)];
  const Projector& proj = rig.projectors[static_cast<std::size_t>(projector)];
  const bool distorted =
      std::any_of(proj.dist.begin(), proj.dist.end(), [](double k) { return k != 0.0; });
  if (distorted && !nominalDepthM) {
    return std::unexpected("projector '" + proj.id +
                           "' has lens distortion: its tables are fitted around the rig's "
                           "nominal depth, and none was given");
  }
  // s = s00 + du·u + dv·v over projector pixels; with u = fx·X/Z + cx, v = fy·Y/Z + cy the
  // plane of s is n₀ − s·e_z with n₀ = (du·fx, dv·fy, s00 + du·cx + dv·cy).
  const double s00 = stripeCoordinate(proj.pattern, proj.width, proj.height, 0.0, 0.0);
  const double du = stripeCoordinate(proj.pattern, proj.width, proj.height, 1.0, 0.0) - s00;
  const double dv = stripeCoordinate(proj.pattern, proj.width, proj.height, 0.0, 1.0) - s00;
  if (!std::isfinite(s00) || (du == 0.0 && dv == 0.0)) {
    return std::unexpected("projector '" + proj.id + "': the stripe pattern is degenerate");
  }
  const Vec3 n0{du * proj.fx(), dv * proj.fy(), s00 + du * proj.cx() + dv * proj.cy()};
  // Camera → projector: X_p = M·X_c + m, M = R_p·R_cᵀ, m = t_p − M·t_c.
  const Mat3 m3 = mulTransposed(proj.R, cam.R);
  const Vec3 mt = mul(m3, cam.t);
  const Vec3 m{proj.t[0] - mt[0], proj.t[1] - mt[1], proj.t[2] - mt[2]};
  if (distorted) {
    return fittedTables(cam, proj, {m3, m}, depthUnitM, *nominalDepthM);
  }
  const double a = -dot(n0, m);
  const double b = m[2];

  const auto pixels = static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height);
  std::vector<double> c(pixels, 0.0);
  std::vector<double> d(pixels, 0.0);
  TriangulationTables t;
  t.width = cam.width;
  t.height = cam.height;
  t.sense.assign(pixels, 0);
  double largest = 0.0;
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const auto n =
          lens::undistort(cam.dist, {(x - cam.cx()) / cam.fx(), (y - cam.cy()) / cam.fy()});
      if (!n) {
        continue;
      }
      const Vec3 mr = mul(m3, {n->x, n->y, 1.0});
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(cam.width) +
                            static_cast<std::size_t>(x);
      c[i] = dot(n0, mr);
      d[i] = -mr[2];
      const double sense = b * c[i] - a * d[i];
      t.sense[i] = static_cast<std::int8_t>(sense > 0 ? 1 : (sense < 0 ? -1 : 0));
      largest = std::max({largest, std::abs(c[i]), std::abs(d[i])});
    }
  }
  if (!(largest > 0.0)) {
    return std::unexpected("triangulation: camera '" + cam.id + "' has no usable pixel ray");
  }
  // 2^k: the largest that keeps |C'|, |D'| ≤ 2^30 and the numerator within 2^62.
  int k = static_cast<int>(std::floor(std::log2(std::ldexp(1.0, 30) / largest)));
  const double sMax = 198.0 * kStripeOne;
  const auto numeratorBound = [&](int e) {
    return std::abs(std::ldexp(a, e) * kStripeOne / depthUnitM) +
           std::abs(std::ldexp(b, e) / depthUnitM) * sMax;
  };
  while (numeratorBound(k) >= std::ldexp(1.0, 62)) {
    --k;
  }
  t.numeratorBase = std::llround(std::ldexp(a, k) * kStripeOne / depthUnitM);
  t.numeratorSlope = std::llround(std::ldexp(b, k) / depthUnitM);
  t.denominatorBase.resize(pixels);
  t.denominatorSlope.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    t.denominatorBase[i] = static_cast<std::int32_t>(std::lround(std::ldexp(c[i], k)));
    t.denominatorSlope[i] = static_cast<std::int32_t>(std::lround(std::ldexp(d[i], k)));
  }
  return t;
}

}  // namespace smx::algo
