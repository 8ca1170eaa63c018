#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

// The BT.601 limited-range YCbCr -> RGB conversion in double precision, derived independently of
// the code under test: the forward matrix (RGB -> Y, Pb, Pr from Kr, Kb) is inverted numerically
// and the limited-range scaling applied to the inputs. Results are rounded to nearest and clamped.
namespace smx::test {

struct RgbDouble {
  double r;
  double g;
  double b;
};

inline RgbDouble yuvToRgbExact(int y, int u, int v) {
  constexpr double kr = 0.299;
  constexpr double kb = 0.114;
  constexpr double kg = 1.0 - kr - kb;
  // Rows: Y, Pb, Pr as functions of (R, G, B).
  const std::array<std::array<double, 3>, 3> m{{
      {kr, kg, kb},
      {-kr / (2 * (1 - kb)), -kg / (2 * (1 - kb)), (1 - kb) / (2 * (1 - kb))},
      {(1 - kr) / (2 * (1 - kr)), -kg / (2 * (1 - kr)), -kb / (2 * (1 - kr))},
  }};
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  // Cramer's rule for (R, G, B) given (Y, Pb, Pr), in 0..1 units.
  const double ey = (y - 16) / 219.0;
  const double pb = (u - 128) / 224.0;
  const double pr = (v - 128) / 224.0;
  const std::array<double, 3> rhs{ey, pb, pr};
  auto solve = [&](int column) {
    auto a = m;
    for (int row = 0; row < 3; ++row) {
      a[static_cast<std::size_t>(row)][static_cast<std::size_t>(column)] =
          rhs[static_cast<std::size_t>(row)];
    }
    return (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
            a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
            a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])) /
           det;
  };
  return {solve(0) * 255.0, solve(1) * 255.0, solve(2) * 255.0};
}

inline int roundClamp8(double value) {
  return static_cast<int>(std::clamp(std::lround(value), 0L, 255L));
}

}  // namespace smx::test
