#pragma once

#include <cstddef>

#include "smx/scan/fusion.hpp"
#include "smx/scan/points.hpp"

// Loose pieces of a fused model: a wrong depth that one view alone saw (a stripe decoded wrong at
// a silhouette, metres behind the object) fuses into a small surface floating apart from the
// object. Pieces of the mesh not connected to a large one are removed, as scanner software's
// "remove isolated parts" does, and the model's points with them.
namespace smx::scan {

struct CleanupReport {
  std::size_t piecesRemoved = 0;
  std::size_t trianglesRemoved = 0;
  std::size_t pointsRemoved = 0;
};

// Keeps the mesh's connected pieces with at least `minShare` of the largest piece's triangles,
// and the model's points within 2 voxels of what is kept.
[[nodiscard]] CleanupReport removeLoosePieces(Mesh& mesh, Cloud& model, double minShare,
                                              double voxelM);

}  // namespace smx::scan
