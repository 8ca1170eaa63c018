#include "fuse_runner.hpp"

#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "output_folder.hpp"
#include "smx/scan/fuse.hpp"
#include "smx/scan/scan_outputs.hpp"
#include "smx/scan/views_folder.hpp"
#include "terminal_text.hpp"

namespace smx::host {
namespace {

using Json = nlohmann::json;

Json vectorJson(const Eigen::Vector3d& v) {
  return Json::array({v.x(), v.y(), v.z()});
}

Json poseJson(const scan::Pose& pose) {
  Json m = Json::array();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      m.push_back(pose.matrix()(r, c));
    }
  }
  return m;
}

Json reportJson(const scan::FuseReport& report, const scan::FuseResult* result,
                const FuseFolderOptions& opts) {
  Json doc;
  doc["format"] = "stripemux-fuse-report/1";
  doc["placement"] = report.placement;
  doc["voxel_mm"] = opts.voxelMm;
  doc["watertight"] = opts.watertight;
  if (opts.watertight) {
    doc["hole_max_mm"] = opts.holeMaxMm;
  }
  doc["views_fused"] = report.fusedViews;
  doc["views_refused"] = report.views.size() - report.fusedViews;
  Json views = Json::array();
  for (const auto& v : report.views) {
    Json j;
    j["id"] = v.id;
    j["fused"] = v.fused;
    if (!v.fused) {
      j["reason"] = v.reason;
    }
    j["fitness"] = v.fitness;
    j["rmse_mm"] = v.rmseM * 1e3;
    j["pose"] = poseJson(v.pose);
    views.push_back(std::move(j));
  }
  doc["views"] = std::move(views);
  if (report.placement == "turntable") {
    doc["loop_closure_mm"] = report.loopClosureM * 1e3;
  }
  if (result != nullptr) {
    doc["model"] = {{"points", result->model.size()},
                    {"extent_min_m", vectorJson(report.extentMin)},
                    {"extent_max_m", vectorJson(report.extentMax)},
                    {"size_mm", vectorJson((report.extentMax - report.extentMin) * 1e3)}};
    doc["mesh"] = {{"vertices", result->mesh.vertices.size()},
                   {"triangles", result->mesh.triangles.size()},
                   {"loose_pieces_removed", report.loosePiecesRemoved}};
  }
  doc["seconds"] = {{"registration", report.registrationS},
                    {"fusion", report.fusionS},
                    {"meshing", report.meshingS}};
  if (const auto& t = opts.tracking) {
    doc["tracking"] = {{"captures", t->captures},
                       {"fused", t->fused},
                       {"lost", t->lost},
                       {"relocalised", t->relocalised},
                       {"track_ms_mean", t->trackMsMean},
                       {"device_frames_dropped", t->deviceFramesDropped}};
  }
  return doc;
}

std::optional<std::string> optionsProblem(const FuseFolderOptions& opts) {
  if (!std::isfinite(opts.voxelMm) || opts.voxelMm < 0.1 || opts.voxelMm > 50) {
    return "--voxel must be 0.1 to 50 mm";
  }
  if (!std::isfinite(opts.holeMaxMm) || opts.holeMaxMm < 0 || opts.holeMaxMm > 1000) {
    return "--hole-max must be 0 to 1000 mm";
  }
  if (opts.minFitness <= 0 || opts.minFitness >= 1 || std::isnan(opts.minFitness)) {
    return "--min-fitness must be between 0 and 1";
  }
  if (opts.axis.empty() != opts.axisPoint.empty()) {
    return "--axis and --axis-point go together";
  }
  for (const double v : opts.axis) {
    if (!std::isfinite(v)) {
      return "--axis must be 3 finite numbers";
    }
  }
  for (const double v : opts.axisPoint) {
    if (!std::isfinite(v)) {
      return "--axis-point must be 3 finite numbers";
    }
  }
  if (!opts.axis.empty() &&
      Eigen::Vector3d(opts.axis[0], opts.axis[1], opts.axis[2]).norm() < 1e-9) {
    return "--axis must not be zero";
  }
  return std::nullopt;
}

}  // namespace

int runFuseFolder(const FuseFolderOptions& opts, const CliStreams& io, std::string_view command) {
  const auto fail = [&io, command](int code, const std::string& message) {
    io.err << command << ": " << printable(message) << "\n";
    return code;
  };
  if (auto problem = optionsProblem(opts)) {
    return fail(kExitUsage, *problem);
  }
  auto folder = scan::readViewsFolder(opts.dir);
  if (!folder) {
    return fail(kExitBadInput, folder.error());
  }
  io.out << "read " << folder->views.size() << " views of " << folder->rig.cameras.size()
         << " cameras from " << opts.dir << "\n";

  scan::FuseOptions options;
  options.voxelM = opts.voxelMm * 1e-3;
  options.registrationVoxelM = std::max(2 * options.voxelM, 0.002);
  options.watertight = opts.watertight;
  options.holeMaxM = opts.holeMaxMm * 1e-3;
  options.refine = opts.refine;
  options.minFitness = opts.minFitness;
  options.tableRadiusM = opts.tableRadiusMm * 1e-3;
  options.axis = folder->axis;
  if (!opts.axis.empty()) {  // the command line wins over the folder's axis
    options.axis = scan::TurntableAxis{
        Eigen::Vector3d(opts.axis[0], opts.axis[1], opts.axis[2]).normalized(),
        Eigen::Vector3d(opts.axisPoint[0], opts.axisPoint[1], opts.axisPoint[2])};
  }
  options.progress = [&io](std::string_view line) { io.out << "  " << line << "\n" << std::flush; };

  auto fused = scan::fuseViews(folder->views, folder->rig, folder->poses, options);
  if (!fused) {
    return fail(kExitBadInput, opts.dir + ": " + fused.error().message);
  }

  // Only now the output folders exist: a failed fusion leaves nothing behind.
  const std::string outDir = opts.out.empty() ? opts.dir : opts.out;
  auto out = OutputFolder::create(outDir);
  if (!out) {
    return fail(kExitDeviceOrIo, out.error());
  }
  auto outViews = OutputFolder::create(std::filesystem::path(outDir) / "views");
  if (!outViews) {
    return fail(kExitDeviceOrIo, outViews.error());
  }
  const auto& result = *fused;
  const auto writeAll = [&]() -> std::expected<void, std::string> {
    for (const auto& [name, writer] : std::vector<std::pair<std::string, OutputFolder::Writer>>{
             {"model.ply", [&](const auto& p) { return scan::writeCloudPly(p, result.model); }},
             {"mesh.ply", [&](const auto& p) { return scan::writeMeshPly(p, result.mesh); }},
             {"mesh.obj", [&](const auto& p) { return scan::writeMeshObj(p, result.mesh); }},
             {"mesh.stl", [&](const auto& p) { return scan::writeMeshStl(p, result.mesh); }}}) {
      if (auto ok = out->write(name, writer); !ok) {
        return ok;
      }
    }
    if (auto ok =
            out->writeText("report.json", reportJson(result.report, &result, opts).dump(2) + "\n");
        !ok) {
      return ok;
    }
    std::vector<std::string> ids;
    for (const auto& v : folder->views) {
      ids.push_back(v.id);
    }
    if (auto ok = outViews->writeText("poses.json", scan::posesJson(ids, result.poses)); !ok) {
      return ok;
    }
    if (auto ok = out->commit(); !ok) {
      return ok;
    }
    return outViews->commit();
  };
  if (auto ok = writeAll(); !ok) {
    return fail(kExitDeviceOrIo, ok.error());
  }
  const Eigen::Vector3d size = (result.report.extentMax - result.report.extentMin) * 1e3;
  io.out << "fused " << result.report.fusedViews << " of " << folder->views.size() << " views ("
         << result.report.placement << "): " << result.model.size() << " points, "
         << result.mesh.triangles.size() << " triangles, " << std::lround(size.x()) << " x "
         << std::lround(size.y()) << " x " << std::lround(size.z()) << " mm\n"
         << "wrote " << outDir << "/model.ply, mesh.ply, mesh.obj, mesh.stl, report.json and "
         << "views/poses.json\n";
  return kExitOk;
}

void addFuseOptions(CLI::App& cmd, FuseFolderOptions& opts) {
  cmd.add_option("--voxel", opts.voxelMm, "TSDF voxel, mm (default 1)");
  cmd.add_flag("--watertight", opts.watertight, "Mesh a closed surface (Screened Poisson)");
  cmd.add_option("--hole-max", opts.holeMaxMm,
                 "With --watertight: holes up to this diameter are closed, mm (default 5)");
  cmd.add_option("--table-radius", opts.tableRadiusMm,
                 "Turntable views: only points within this of the axis, mm (default 250; 0 all)")
      ->check(CLI::Range(0.0, 10000.0));
  cmd.add_flag("--refine", opts.refine,
               "Refine given and turntable poses by registration and a pose graph (default: "
               "given poses as they are, turntable views by their angles about the axis)");
  cmd.add_option("--min-fitness", opts.minFitness,
                 "A view registering to less than this share of points is refused (0.3)");
}

}  // namespace smx::host
