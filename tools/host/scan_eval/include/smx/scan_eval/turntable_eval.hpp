#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

// The turntable scan's figures (`stripemux eval --only scan`, docs/scan-results.md): a named scene
// whose objects stand on a turntable, rendered at N table angles with realistic optics, decoded by
// the firmware's pipeline, fused by the host's scan library, and the mesh compared with the true
// surface. Host code; throws std::runtime_error naming the step that failed.
namespace smx::scan_eval {

struct TurntableEvalOptions {
  std::string scene = "bunny_turntable";
  std::string rigFile = "rig_2proj_1cam.json";  // boards/sim/<rigFile>
  int views = 24;
  double voxelM = 0.001;
  double tableRadiusM = 0.25;  // the scan volume round the table's axis
  int supersampling = 0;       // 0: the scene's own
  std::uint64_t seed = 1;
  bool realism = true;  // the renderer's realism options (addRealism), as real optics have
  std::function<void(const std::string&)> progress{};
};

// The fused mesh with the range cleaning's margin at holes and depth jumps set to edgePx.
struct MarginResult {
  int edgePx = 0;
  double meanMm = 0.0;
  double p95Mm = 0.0;
  double coverage = 0.0;
};

struct TurntableEvalResult {
  std::string scene;
  std::string rigFile;
  int views = 0;
  int fusedViews = 0;
  double meanMm = 0.0;  // fused mesh vertices to the true surface
  double p95Mm = 0.0;
  // Of the scanned object's true surface the views can see (visible from a camera and lit by a
  // projector in some view; the scene's meshes on the table, not its platter), the share within
  // 1 mm of the fused mesh.
  double coverage = 0.0;
  // The rest of that surface, by where it was lost: never decoded (no view's depth within 2 mm of
  // it), decoded but removed by the table crop or the range cleaning, or kept but without the
  // mesh within 1 mm (fusion, meshing or the loose-piece removal).
  double missedUndecoded = 0.0;
  double missedCleaned = 0.0;
  double missedUnmeshed = 0.0;
  // The share of that surface some view sees within 60° of head-on, and its coverage: the part
  // a single ring of views can be asked to cover.
  double wellSeenShare = 0.0;
  double wellSeenCoverage = 0.0;
  double loopClosureMm = 0.0;
  double fuseS = 0.0;    // registration, fusion and meshing after the last view
  double decodeS = 0.0;  // rendering and decoding every view (not part of the scan's time)
  std::size_t meshVertices = 0;
  // The scan's own margin first, then each narrower one down to 0: what the margin trades.
  std::vector<MarginResult> margins;
};

[[nodiscard]] TurntableEvalResult runTurntableEval(const TurntableEvalOptions& options);

}  // namespace smx::scan_eval
