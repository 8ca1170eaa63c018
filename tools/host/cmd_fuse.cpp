// stripemux fuse DIR [--out DIR2] [--voxel MM] [--watertight] [--hole-max MM] [--axis X,Y,Z
//                    --axis-point X,Y,Z] [--refine] [--min-fitness F]
// Recorded range views (a `scan` folder or a `stream` folder) registered, fused and meshed
// (docs/scanning.md): DIR2 gets model.ply, mesh.ply, mesh.obj, mesh.stl, report.json and
// views/poses.json, all or none of them.
#include <memory>

#include "commands.hpp"
#include "fuse_runner.hpp"

namespace smx::host {

void addFuseCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<FuseFolderOptions>();
  auto* cmd = app.add_subcommand(
      "fuse", "Register, fuse and mesh recorded range views (a scan's or stream's folder)");
  cmd->add_option("dir", opts->dir, "The views folder (docs/scanning.md)")->required();
  cmd->add_option("--out", opts->out, "Where the model goes (default: DIR)");
  addFuseOptions(*cmd, *opts);
  cmd->add_option("--axis", opts->axis, "Turntable axis direction X,Y,Z (rig frame)")
      ->delimiter(',')
      ->expected(3);
  cmd->add_option("--axis-point", opts->axisPoint, "A point on the turntable axis X,Y,Z, metres")
      ->delimiter(',')
      ->expected(3);
  cmd->callback([opts, &io, &exitCode] { exitCode = runFuseFolder(*opts, io, "stripemux fuse"); });
}

}  // namespace smx::host
