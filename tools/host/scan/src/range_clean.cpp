#include "smx/scan/range_clean.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "smx/algo/lens.hpp"

namespace smx::scan {

namespace {

std::size_t at(const CameraRange& r, int x, int y) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(r.width) +
         static_cast<std::size_t>(x);
}

// 1 where a pixel has no depth or a 4-neighbour jumps by more than jumpPerPx of its depth.
std::vector<std::uint8_t> edges(const CameraRange& r, double jumpPerPx) {
  std::vector<std::uint8_t> edge(r.depth.size(), 0);
  for (int y = 0; y < r.height; ++y) {
    for (int x = 0; x < r.width; ++x) {
      const double z = r.depth[at(r, x, y)];
      if (z == 0) {
        edge[at(r, x, y)] = 1;
        continue;
      }
      for (const auto& [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        const int nx = x + dx;
        const int ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= r.width || ny >= r.height) {
          continue;
        }
        const double n = r.depth[at(r, nx, ny)];
        if (n == 0 || std::abs(n - z) > jumpPerPx * z) {
          edge[at(r, x, y)] = 1;
        }
      }
    }
  }
  return edge;
}

// Max filter of `mask` over a (2·radius + 1)² square, separably.
std::vector<std::uint8_t> dilated(const std::vector<std::uint8_t>& mask, int width, int height,
                                  int radius) {
  std::vector<std::uint8_t> rows(mask.size(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      std::uint8_t v = 0;
      for (int k = std::max(0, x - radius); k <= std::min(width - 1, x + radius) && v == 0; ++k) {
        v = mask[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                 static_cast<std::size_t>(k)];
      }
      rows[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(x)] = v;
    }
  }
  std::vector<std::uint8_t> out(mask.size(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      std::uint8_t v = 0;
      for (int k = std::max(0, y - radius); k <= std::min(height - 1, y + radius) && v == 0; ++k) {
        v = rows[static_cast<std::size_t>(k) * static_cast<std::size_t>(width) +
                 static_cast<std::size_t>(x)];
      }
      out[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
          static_cast<std::size_t>(x)] = v;
    }
  }
  return out;
}

}  // namespace

void cleanForFusion(RangeView& view, const algo::Rig& rig, const RangeCleanOptions& options) {
  const double minCos = std::cos(options.maxIncidenceDeg * std::numbers::pi / 180.0);
  for (std::size_t c = 0; c < view.cameras.size() && c < rig.cameras.size(); ++c) {
    const algo::Camera& camera = rig.cameras[c];
    CameraRange& r = view.cameras[c];
    if (r.width != camera.width || r.height != camera.height || r.depth.empty()) {
      continue;
    }
    const auto edge = edges(r, options.jumpPerPx);
    const auto drop = options.edgePx > 0 ? dilated(edge, r.width, r.height, options.edgePx) : edge;
    // Camera-frame points, for the normals.
    std::vector<std::optional<Eigen::Vector3d>> points(r.depth.size());
    for (int y = 0; y < r.height; ++y) {
      for (int x = 0; x < r.width; ++x) {
        const std::uint16_t z = r.depth[at(r, x, y)];
        if (z == 0) {
          continue;
        }
        if (const auto p = algo::lens::devicePoint(
                camera, {static_cast<double>(x), static_cast<double>(y)}, z * view.depthUnitM)) {
          points[at(r, x, y)] = Eigen::Vector3d((*p)[0], (*p)[1], (*p)[2]);
        }
      }
    }
    std::vector<std::uint16_t> kept(r.depth.size(), 0);
    for (int y = 1; y + 1 < r.height; ++y) {
      for (int x = 1; x + 1 < r.width; ++x) {
        const auto& p = points[at(r, x, y)];
        if (!p || (options.edgePx > 0 && drop[at(r, x, y)] != 0)) {
          continue;
        }
        const auto& right = points[at(r, x + 1, y)];
        const auto& left = points[at(r, x - 1, y)];
        const auto& down = points[at(r, x, y + 1)];
        const auto& up = points[at(r, x, y - 1)];
        if (!right || !left || !down || !up) {
          continue;
        }
        const Eigen::Vector3d normal = (*right - *left).cross(*down - *up);
        if (normal.norm() == 0 || std::abs(normal.normalized().dot(p->normalized())) < minCos) {
          continue;  // grazing: the ray runs along the surface
        }
        kept[at(r, x, y)] = r.depth[at(r, x, y)];
      }
    }
    r.depth = std::move(kept);
  }
}

}  // namespace smx::scan
