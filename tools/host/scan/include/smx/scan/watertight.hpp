#pragma once

#include <expected>
#include <string>

#include "smx/scan/fusion.hpp"
#include "smx/scan/points.hpp"

// A closed surface from an oriented cloud: Screened Poisson reconstruction, then the parts far
// from any input point removed so that only holes up to a size are filled (docs/scanning.md).
namespace smx::scan {

struct WatertightOptions {
  double voxelM = 0.001;    // the model's resolution: sets the Poisson octree depth
  double holeMaxM = 0.005;  // holes up to this diameter are closed, larger ones stay open
};

// The Poisson surface of `cloud` (needs normals) with every vertex farther than holeMaxM / 2
// from an input point removed, with its triangles. A hole of diameter d ≤ holeMaxM is closed;
// a larger one stays open, shrunk by about holeMaxM / 2 around its rim. Colours are those of
// the nearest input point.
[[nodiscard]] std::expected<Mesh, std::string> watertightMesh(const Cloud& cloud,
                                                              const WatertightOptions& options);

}  // namespace smx::scan
