#pragma once

#include <expected>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/scan/fusion.hpp"
#include "smx/scan/points.hpp"
#include "smx/scan/range_clean.hpp"
#include "smx/scan/range_view.hpp"
#include "smx/scan/registration.hpp"

// Views → one model (docs/scanning.md "Fusing views"): place each view (given pose, turntable
// angle about the axis, or sequential ICP), refine with ICP to its neighbours and a pose graph
// that closes the loop, refuse views that do not overlap, fuse into a TSDF and mesh.
namespace smx::scan {

struct FuseOptions {
  double voxelM = 0.001;                // TSDF voxel; truncation 4 voxels
  bool watertight = false;              // mesh by Screened Poisson instead of the TSDF's surface
  double holeMaxM = 0.005;              // with watertight: holes up to this are closed
  std::optional<TurntableAxis> axis{};  // places views with turntable angles
  // With turntable angles and an axis: only points within this of the axis are used (what stands
  // on the table; table_crop.hpp). 0: every point.
  double tableRadiusM = 0.25;
  // Range pixels a model should not take (range_clean.hpp); edgePx 0 and 90° keep every pixel.
  RangeCleanOptions clean{};
  // Mesh pieces with fewer triangles than this share of the largest piece's are removed
  // (model_cleanup.hpp); 0 keeps every piece.
  double minPieceShare = 0.02;
  // Refine given poses, and turntable poses, by registration and a pose graph. Off: given poses
  // are used as they are, and turntable views are placed by their angles about the (calibrated)
  // axis, their registrations only judging the overlap (decoded depth's small view-dependent
  // errors would otherwise turn the views off the true axis).
  bool refine = false;
  double minFitness = 0.3;            // a view registering below this is refused
  double registrationVoxelM = 0.002;  // the clouds registration works on (finest ICP level)
  std::function<void(std::string_view)> progress{};  // one line per step, when set
};

struct ViewReport {
  std::string id{};
  bool fused = false;
  std::string reason{};  // why not fused
  double fitness = 0.0;  // of its registration (1 when placed as given)
  double rmseM = 0.0;
  Pose pose = Pose::Identity();
};

struct FuseReport {
  std::string placement{};  // "given", "turntable", "sequential"
  std::vector<ViewReport> views{};
  std::size_t fusedViews = 0;
  Eigen::Vector3d extentMin = Eigen::Vector3d::Zero();  // the model's bounding box, model frame
  Eigen::Vector3d extentMax = Eigen::Vector3d::Zero();
  double loopClosureM = 0.0;  // turntable: gap between the last view's pose chained to the first
  std::size_t loosePiecesRemoved = 0;  // model_cleanup.hpp
  double registrationS = 0.0;
  double fusionS = 0.0;
  double meshingS = 0.0;
};

struct FuseResult {
  Cloud model{};
  Mesh mesh{};
  std::vector<Pose> poses;  // one per view (refused views: their last estimate)
  FuseReport report{};
};

struct FuseError {
  std::string message{};
  FuseReport report{};  // as far as it got
};

// The rig at table angle `deg` seen from the table at angle 0: the object turned by +deg about
// the axis, so its points go back by −deg.
[[nodiscard]] Pose turntablePose(const TurntableAxis& axis, double deg);

// What the model takes of each view: a turntable's views (every view with an angle, an axis and
// a table radius given) only what turns with the table, and no view its edges or grazing pixels.
[[nodiscard]] std::vector<RangeView> viewsForFusion(const std::vector<RangeView>& input,
                                                    const algo::Rig& rig,
                                                    const FuseOptions& options);

// `givenPoses` is empty or one per view (the views as given; fuseViews takes viewsForFusion of
// them). Fewer than 2 views fused is an error.
[[nodiscard]] std::expected<FuseResult, FuseError> fuseViews(
    const std::vector<RangeView>& input, const algo::Rig& rig,
    const std::vector<std::optional<Pose>>& givenPoses, const FuseOptions& options = {});

}  // namespace smx::scan
