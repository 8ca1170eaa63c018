#include "smx/health/attribution.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include "smx/algo/arena.hpp"
#include "smx/algo/triangulation.hpp"
#include "smx/health/drift.hpp"

namespace smx::health {

namespace {

constexpr int kPoseParameters = 6;
constexpr double kShiftM = 0.001;
constexpr double kTurnRad = 0.2 * std::numbers::pi / 180.0;

// Tables and the memory the triangulator lives in.
struct OwnedTriangulator {
  std::vector<std::byte> memory;
  algo::Triangulator triangulator;
};

std::expected<OwnedTriangulator, std::string> makeTriangulator(
    const algo::Rig& rig, int camera, int projector, const algo::PipelineOptions& options) {
  const auto tables = algo::buildTriangulationTables(rig, camera, projector, options.depthUnitM,
                                                     options.nominalDepthM);
  if (!tables) {
    return std::unexpected(tables.error());
  }
  const auto bytes = algo::Triangulator::workspaceBytes(*tables);
  if (!bytes) {
    return std::unexpected(bytes.error().message);
  }
  std::vector<std::byte> memory(*bytes);
  algo::Arena arena(memory);
  auto triangulator = algo::Triangulator::create(*tables, arena);
  if (!triangulator) {
    return std::unexpected(triangulator.error().message);
  }
  // The arena's buffer moves with the vector (its heap block stays where it is).
  return OwnedTriangulator{std::move(memory), *triangulator};
}

// Per inlier block: the mean change of projector r's depth under each pose parameter (mm at the
// reference distance, as the disagreement).
using Columns = std::vector<std::array<double, kPoseParameters>>;

std::expected<Columns, std::string> poseColumns(const algo::Rig& rig, const CameraDepths& depths,
                                                int r, int other, const Disagreement& d,
                                                const algo::PipelineOptions& options, int blockPx) {
  auto base = makeTriangulator(rig, depths.camera, r, options);
  if (!base) {
    return std::unexpected(base.error());
  }
  Columns columns(d.inliers.size());
  for (int k = 0; k < kPoseParameters; ++k) {
    Drift drift;
    if (k < 3) {
      drift.shiftM[static_cast<std::size_t>(k)] = kShiftM;
    } else {
      drift.rotationRad[static_cast<std::size_t>(k - 3)] = kTurnRad;
    }
    auto moved = makeTriangulator(withDrift(rig, r, drift), depths.camera, r, options);
    if (!moved) {
      return std::unexpected(moved.error());
    }
    const auto& stripe = depths.stripe[static_cast<std::size_t>(r)];
    for (std::size_t b = 0; b < d.inliers.size(); ++b) {
      double sum = 0;
      int n = 0;
      const int x0 = d.inliers[b].bx * blockPx;
      const int y0 = d.inliers[b].by * blockPx;
      for (int y = y0; y < std::min(depths.height, y0 + blockPx); ++y) {
        for (int x = x0; x < std::min(depths.width, x0 + blockPx); ++x) {
          const std::size_t i = depths.index(x, y);
          if (depths.depth[static_cast<std::size_t>(other)][i] == algo::kNoDepth ||
              depths.depth[static_cast<std::size_t>(r)][i] == algo::kNoDepth) {
            continue;
          }
          const int z0 = base->triangulator.depthAt(x, y, stripe[i]);
          const int z1 = moved->triangulator.depthAt(x, y, stripe[i]);
          if (z0 != algo::kNoDepth && z1 != algo::kNoDepth) {
            sum +=
                atReferenceDistance((z1 - z0) * depths.depthUnitM * 1000.0, z0 * depths.depthUnitM);
            ++n;
          }
        }
      }
      columns[b][static_cast<std::size_t>(k)] = n > 0 ? sum / n : 0.0;
    }
  }
  return columns;
}

// RMS residual of the least-squares fit of the columns to the block medians (ridge-regularised:
// a pose change along a projector's stripes moves nothing, and its column is zero).
double fitResidual(const Columns& columns, const Disagreement& d) {
  constexpr std::size_t kN = kPoseParameters;
  std::array<std::array<double, kN + 1>, kN> m{};
  for (std::size_t b = 0; b < columns.size(); ++b) {
    for (std::size_t r = 0; r < kN; ++r) {
      for (std::size_t c = 0; c < kN; ++c) {
        m[r][c] += columns[b][r] * columns[b][c];
      }
      m[r][kN] += columns[b][r] * d.inliers[b].mm;
    }
  }
  double trace = 0;
  for (std::size_t r = 0; r < kN; ++r) {
    trace += m[r][r];
  }
  for (std::size_t r = 0; r < kN; ++r) {
    m[r][r] += 1e-9 * trace + 1e-12;
  }
  for (std::size_t c = 0; c < kN; ++c) {  // Gauss–Jordan; the ridge keeps it positive definite
    for (std::size_t r = 0; r < kN; ++r) {
      if (r != c) {
        const double f = m[r][c] / m[c][c];
        for (std::size_t k = c; k <= kN; ++k) {
          m[r][k] -= f * m[c][k];
        }
      }
    }
  }
  double sumSquares = 0;
  for (std::size_t b = 0; b < columns.size(); ++b) {
    double model = 0;
    for (std::size_t r = 0; r < kN; ++r) {
      model += columns[b][r] * m[r][kN] / m[r][r];
    }
    const double e = d.inliers[b].mm - model;
    sumSquares += e * e;
  }
  return std::sqrt(sumSquares / static_cast<double>(columns.size()));
}

}  // namespace

std::expected<Attribution, std::string> attributeByShape(
    const algo::Rig& rig, const CameraDepths& depths, int projector, int otherProjector,
    const Disagreement& disagreement, const algo::PipelineOptions& options, int blockPx) {
  Attribution a;
  const std::array<int, 2> pair{projector, otherProjector};
  for (std::size_t i = 0; i < 2; ++i) {
    const auto columns =
        poseColumns(rig, depths, pair[i], pair[1 - i], disagreement, options, blockPx);
    if (!columns) {
      return std::unexpected(rig.projectors[static_cast<std::size_t>(pair[i])].id + ": " +
                             columns.error());
    }
    a.residualMm[i] = fitResidual(*columns, disagreement);
  }
  if (a.residualMm[0] <= kDecisiveRatio * a.residualMm[1]) {
    a.named = 0;
  } else if (a.residualMm[1] <= kDecisiveRatio * a.residualMm[0]) {
    a.named = 1;
  }
  return a;
}

}  // namespace smx::health
