#pragma once

#include <cstddef>
#include <cstdint>
#include <expected>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "smx/algo/arena.hpp"
#include "smx/algo/error.hpp"
#include "smx/algo/range_image.hpp"
#include "smx/algo/rig.hpp"

// Triangulation of a decoded stripe coordinate (paper ref [20]; DESIGN.md item 8;
// docs/triangulation.md). The stripe coordinate s of projector p is affine in the projector's
// pixel coordinates, so with an undistorted projector a value of s is a plane through the
// projector centre: n(s)·X_p = 0 with n(s) = n₀ − s·(0, 0, 1). A camera pixel's undistorted ray
// is z·r, r = (x_n, y_n, 1), in the camera frame, and X_p = M·X_c + m (camera → projector), so
//
//     z = (A + B·s) / (C + D·s),   A = −n₀·m, B = m_z, C = n₀·(M·r), D = −(M·r)_z,
//
// A, B per projector–camera pair, C, D per camera pixel. The point lies in front of the
// projector when (B·C − A·D) and (C + D·s) have the same sign (Z_p = (B·C − A·D) / (C + D·s)).
//
// With a distorted projector (k1 k2 p1 p2 k3, as the camera) z along one pixel's ray is no longer
// a Möbius function of s (the distortion is cubic and more along the epipolar line), but over the
// working depths it is close to z = (A + B·s + E·s² + F·s³) / (C + D·s): each pixel gets its
// own A, B, E, F, C, D, exact at five depths (Chebyshev nodes in 1/z over the working range),
// and the build measures the fit against exact s(z) and refuses a projector it cannot follow.
namespace smx::algo {

// The working range a distorted projector's tables are fitted over: kFitNearFactor to
// kWorkingRangeFactor times the nominal depth (camera z). Outside it depth is still computed,
// without an accuracy promise.
inline constexpr double kFitNearFactor = 0.5;
// The largest fit residual (|depth of the fit − exact depth| for exact s) accepted at the nominal
// depth: the "triangulation of exact truth within 0.1 mm".
inline constexpr double kMaxFitResidualM = 0.0001;
// Pixels where the fit misses kMaxFitResidualM get no depth; a projector losing more than this
// share of the pixels it lights at the nominal depth is refused.
inline constexpr double kMaxFitMissedShare = 0.01;

// Init-time tables for one projector–camera pair, in integers (buildTriangulationTables).
// Numerics: s is Q16 (StripeQ16). den = (C' << 16) + D'·s with C', D' int32 (the per-pixel C, D
// times 2^k, k the largest that keeps every |C'| and |D'| ≤ 2^30), so |den| < 2^47 + 2^54.
// num = A' + B'·s, int64, A' and B' the constants A, B times 2^k·2^16 / depthUnitM (resp. 2^k /
// depthUnitM), so that z in depth units is num / den; buildTriangulationTables lowers k until
// |A'| + |B'|·198·2^16 < 2^62 for every pixel. The rounding of C', D' to integers is ≤ 2^-31
// of their range. A distorted projector's numerator is per pixel (PixelNumerator) and so is k:
// each pixel's A, B, E, F, C, D are scaled so that max(|C|, |D|) = 1 and C + D·s > 0 over the
// working range (sense is then +1), times 2^k with k = 30 lowered until
// |A'| + (|B'|·198 + |E'|·198² + |F'|·198³)·2^16 < 2^62 (the num of any s in range fits int64).
//
// With s2 = ⌊s·s / 2^16⌋ and s3 = ⌊s2·s / 2^16⌋ (s ≥ 0; Q16 stripe² and stripe³, < 2^31.2 and
// 2^38.9): num = A' + B'·s + E'·s2 + F'·s3, E' = E·2^k / depthUnitM, F' = F·2^k / depthUnitM.
struct PixelNumerator {
  std::int64_t base = 0;    // A'
  std::int64_t slope = 0;   // B'
  std::int64_t square = 0;  // E'
  std::int64_t cube = 0;    // F'
};

struct TriangulationTables {
  int width = 0;
  int height = 0;
  std::int64_t numeratorBase = 0;              // A' (undistorted projector)
  std::int64_t numeratorSlope = 0;             // B' (per Q16 unit of s)
  std::vector<PixelNumerator> numerators;      // per pixel (distorted projector; else empty)
  std::vector<std::int32_t> denominatorBase;   // C' per pixel, row-major
  std::vector<std::int32_t> denominatorSlope;  // D' per pixel
  // sign(B·C − A·D) per pixel (+1 for a fitted one); 0 where the pixel has no ray or, with a
  // distorted projector, s(z) along it is not defined and monotone over the working range.
  std::vector<std::int8_t> sense;
  // Distorted projector: the fit's largest |z_fit(s) − z| for exact s over the pixels kept whose
  // point lands inside the projector image and the stripe sequence, at the nominal depth and
  // over the working range (17 depths, even in 1/z), metres; 0 for an undistorted projector.
  double nominalResidualM = 0.0;
  double rangeResidualM = 0.0;
};

// The tables for camera `camera` and projector `projector` of the rig, depth in units of
// depthUnitM metres. A distorted projector's tables are fitted around nominalDepthM (the rig's
// working distance; required then, ignored otherwise). Errors name the problem: indices,
// depthUnitM or nominalDepthM ≤ 0, a degenerate pattern, a distorted projector whose fit misses
// kMaxFitResidualM at the nominal depth on more than kMaxFitMissedShare of the pixels it lights
// (the message gives the share and the largest miss); fewer such pixels get no depth.
[[nodiscard]] std::expected<TriangulationTables, std::string> buildTriangulationTables(
    const Rig& rig, int camera, int projector, double depthUnitM,
    std::optional<double> nominalDepthM = std::nullopt);

// Distance between the camera's and the projector's centres, metres (the triangulation
// baseline; evaluation converts depth errors into disparity with it).
[[nodiscard]] double baselineM(const Rig& rig, int camera, int projector);

class Triangulator {
 public:
  // Stripe coordinates at or beyond the end of the sequence are not triangulated (they also
  // bound the tables' integer ranges).
  static constexpr StripeQ16 kMaxStripe = 198 * kStripeOne;

  // The per-pixel tables as plain pointers, with the depth formula: a loop that stores bytes
  // (which may alias anything) keeps these in registers, where it would reload the spans after
  // every store.
  struct Lookup {
    const std::int32_t* base = nullptr;
    const std::int32_t* slope = nullptr;
    const std::int8_t* sense = nullptr;
    const PixelNumerator* numerators = nullptr;  // per pixel, for a distorted projector
    std::int64_t numeratorBase = 0;
    std::int64_t numeratorSlope = 0;

    // depthAt for the pixel of index y · width + x. kPerPixel: perPixelNumerators() (chosen
    // once per loop, so that the shared-numerator loop does no extra work).
    template <bool kPerPixel>
    [[nodiscard]] std::uint16_t depth(std::size_t i, StripeQ16 s) const {
      const std::int8_t sign = sense[i];
      if (s < 0 || s >= kMaxStripe || sign == 0) {  // kNoStripe is negative
        return kNoDepth;
      }
      std::int64_t den = (std::int64_t{base[i]} << 16) + std::int64_t{slope[i]} * s;
      std::int64_t num = 0;
      if constexpr (kPerPixel) {
        const PixelNumerator& n = numerators[i];
        const std::int64_t s2 = (std::int64_t{s} * s) >> 16;  // s ≥ 0 here: the floor
        const std::int64_t s3 = (s2 * s) >> 16;
        num = n.base + n.slope * s + n.square * s2 + n.cube * s3;
      } else {
        num = numeratorBase + numeratorSlope * s;
      }
      if (den == 0 || (den > 0) != (sign > 0)) {
        return kNoDepth;
      }
      if (den < 0) {
        den = -den;
        num = -num;
      }
      if (num <= 0) {
        return kNoDepth;
      }
      const std::int64_t z = (num + den / 2) / den;
      return z >= 1 && z <= 65535 ? static_cast<std::uint16_t>(z) : kNoDepth;
    }
  };

  // For tables of an undistorted projector (9 bytes per pixel).
  [[nodiscard]] static Result<std::size_t> workspaceBytes(int width, int height);
  // For these tables (41 bytes per pixel with per-pixel numerators).
  [[nodiscard]] static Result<std::size_t> workspaceBytes(const TriangulationTables& tables);
  // Copies the tables into the arena.
  [[nodiscard]] static Result<Triangulator> create(const TriangulationTables& tables, Arena& arena);

  // z in depth units for pixel (x, y) (inside the image) and stripe coordinate s; kNoDepth
  // where s is kNoStripe, the pixel has no ray, the point is behind the camera or the projector,
  // the ray is (nearly) parallel to the plane, or z is not within 1…65535 units, and for s outside
  // [0, kMaxStripe). Rounded half up.
  [[nodiscard]] std::uint16_t depthAt(int x, int y, StripeQ16 s) const {
    const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                          static_cast<std::size_t>(x);
    const Lookup l = lookup();
    return perPixelNumerators() ? l.depth<true>(i, s) : l.depth<false>(i, s);
  }

  // Whether the numerators are per pixel (a distorted projector): Lookup::depth's kPerPixel.
  [[nodiscard]] bool perPixelNumerators() const { return !numerators_.empty(); }

  [[nodiscard]] Lookup lookup() const {
    return {base_.data(),       slope_.data(),  sense_.data(),
            numerators_.data(), numeratorBase_, numeratorSlope_};
  }

  // depthAt for every pixel. Both planes must be width × height.
  [[nodiscard]] Result<void> run(ConstStripePlane stripe, DepthPlane depth) const;

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }

 private:
  Triangulator() = default;

  template <bool kPerPixel>
  void runRows(ConstStripePlane stripe, DepthPlane depth) const;

  int width_ = 0;
  int height_ = 0;
  std::int64_t numeratorBase_ = 0;
  std::int64_t numeratorSlope_ = 0;
  std::span<PixelNumerator> numerators_;
  std::span<std::int32_t> base_;
  std::span<std::int32_t> slope_;
  std::span<std::int8_t> sense_;
};

}  // namespace smx::algo
