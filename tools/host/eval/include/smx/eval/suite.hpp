#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "smx/algo/demux.hpp"
#include "smx/eval/boundary_eval.hpp"
#include "smx/eval/depth_eval.hpp"
#include "smx/eval/frame_eval.hpp"
#include "smx/eval/realism_case.hpp"
#include "smx/eval/realism_eval.hpp"
#include "smx/eval/sim_frame.hpp"
#include "smx/eval/table2.hpp"

// The evaluation suite behind `stripemux eval` (docs/results.md): the named scenes rendered by
// the simulator and decoded by the firmware's camera pipeline, scored against the truth, plus
// flat targets, the paper's Table 2, baselines and robustness sweeps. Deterministic for a seed.
// Host code; throws std::runtime_error naming the scene or step that failed.
namespace smx::eval {

// One camera of one scene: figures and the merged range image's error map.
struct SceneRun {
  std::string scene;
  std::string rigFile;
  int camera = 0;
  FrameFigures figures;
  std::vector<float> errorMm;  // merged depth − truth, mm, NaN without data (width × height)
  int width = 0;
  int height = 0;
};

// A flat target: fill rate and plane-fit RMS in the smooth lit region, plus the truth's RMSE.
struct FlatRun {
  std::string target;
  double distanceM = 0;
  PlaneFit fit;
  DepthScore score;
};

// A conventional single-projector scan of the same scene against the multi-projector one:
// coverage of everything the camera sees (not only what is lit).
struct CoverageRun {
  std::string scene;
  std::string rigFile;
  int projectors = 0;
  DepthScore view;  // the merged range image over every pixel where the camera sees a surface
};

// Boundary scores of one projector in the region lit by exactly `patterns` projectors.
struct BoundaryRun {
  std::string scene;
  int projector = 0;
  int patterns = 0;
  BoundaryScore demux;
  BoundaryScore other;  // the baseline's (direct colour; or demux with true directions)
};

// The pipeline with its direction estimation replaced by the true directions.
struct TrueDirectionRun {
  std::string scene;
  std::string rigFile;
  FrameFigures estimated;
  FrameFigures truth;
  std::vector<BoundaryRun> boundaries;  // per projector, lit by ≥ 1 smooth (demux vs true dirs)
};

struct SweepPoint {
  double value = 0;
  double stripeWidthPx = 0;  // median stripe width in the camera image (truth), pixels
  FrameFigures figures;
};
struct Sweep {
  std::string name;      // "noise", "ambient", ...
  std::string quantity;  // what value is, with its unit
  std::string setup;     // scene and rig, what is varied
  std::vector<SweepPoint> points;
};

// The randomised realism suite (realism_case.hpp, realism_eval.hpp): one run per camera of each
// generated case; the camera image and error map are kept for the kRealismWorstShown worst runs.
inline constexpr int kRealismWorstShown = 5;
struct RealismReport {
  int cases = 0;
  RealismOptions generator;
  std::vector<RealismRun> runs;
};

struct Report {
  std::uint64_t seed = 1;
  int supersampling = 0;
  std::vector<SceneRun> scenes;
  std::vector<FlatRun> flat;
  std::vector<FlatRun> distance;
  std::vector<Table2Row> table2;
  std::vector<CoverageRun> singleProjector;
  std::vector<BoundaryRun> directColour;
  std::vector<TrueDirectionRun> trueDirections;
  std::vector<Sweep> sweeps;
  RealismReport realism;
  double seconds = 0;
};

enum class Section : std::uint8_t { kScenes, kFlat, kTable2, kBaselines, kSweeps, kRealism };
[[nodiscard]] std::vector<Section> allSections();
[[nodiscard]] const char* sectionName(Section section);

struct SuiteOptions {
  std::uint64_t seed = 1;
  int supersampling = 0;  // samples per pixel side of every render; 0: the scenes' own (2)
  std::vector<Section> sections = allSections();
  std::vector<std::string> scenes;  // empty: every scene of the suite
  int realismCases = 60;            // generated cases of the realism section
  RealismOptions realism;
  std::function<void(const std::string&)> progress;  // one line per finished run
};

[[nodiscard]] Report runSuite(const SuiteOptions& options);

// Per-tile true encoding directions of every projector from the truth stripe planes, in
// Demultiplexer::fixTileDirections' layout; tiles a projector does not light keep `fallback`'s.
[[nodiscard]] std::vector<algo::TileDirection> trueTileDirections(
    const SimFrame& frame, const algo::DemuxLayout& layout,
    std::span<const algo::TileDirection> fallback);

}  // namespace smx::eval
