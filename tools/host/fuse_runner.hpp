#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli.hpp"

// Registration, fusion and meshing of a views folder into the scan's outputs
// (docs/scanning.md): what `stripemux fuse` does, and `stripemux scan` after its captures.
namespace smx::host {

// A hand-held scan's tracking, for report.json's "tracking".
struct TrackingSummary {
  int captures = 0;
  int fused = 0;
  int lost = 0;
  int relocalised = 0;
  double trackMsMean = 0.0;
  std::uint64_t deviceFramesDropped = 0;  // frames the host was too slow for
};

struct FuseFolderOptions {
  std::string dir;
  std::string out;  // empty: dir
  double voxelMm = 1.0;
  bool watertight = false;
  double holeMaxMm = 5.0;
  std::vector<double> axis;  // empty, or X,Y,Z with axisPoint
  std::vector<double> axisPoint;
  bool refine = false;
  double minFitness = 0.3;
  double tableRadiusMm = 250.0;
  std::optional<TrackingSummary> tracking{};
};

// The options fuse and scan share: --voxel, --watertight, --hole-max, --table-radius, --refine,
// --min-fitness.
void addFuseOptions(CLI::App& cmd, FuseFolderOptions& opts);

// DIR2 gets model.ply, mesh.ply, mesh.obj, mesh.stl, report.json and views/poses.json, all or
// none. Returns the exit code; messages start with `command`.
[[nodiscard]] int runFuseFolder(const FuseFolderOptions& opts, const CliStreams& io,
                                std::string_view command);

}  // namespace smx::host
