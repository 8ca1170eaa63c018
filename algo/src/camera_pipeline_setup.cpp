// Init time: the camera pipeline's tables from the rig.
#include <algorithm>
#include <cmath>
#include <string>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/encoding_prediction.hpp"

namespace smx::algo {

std::expected<CameraPipelineSetup, std::string> prepareCameraPipeline(
    const Rig& rig, int camera, const PipelineOptions& options) {
  if (camera < 0 || camera >= static_cast<int>(rig.cameras.size())) {
    return std::unexpected("no camera " + std::to_string(camera) + " in the rig");
  }
  const Camera& cam = rig.cameras[static_cast<std::size_t>(camera)];
  CameraPipelineSetup setup;
  setup.layout = {cam.width, cam.height, static_cast<int>(rig.projectors.size()), options.demux};
  setup.decode = options.decode;
  setup.edgeJumpPermille = options.edgeJumpPermille;
  // More lanes than projectors would have nothing to do.
  setup.lanes = std::clamp(options.lanes, 1, setup.layout.projectors);
  setup.depthUnitM = options.depthUnitM;
  auto angles = predictEncodingAngles(rig, camera, setup.layout, options.nominalDepthM);
  if (!angles) {
    return std::unexpected(angles.error());
  }
  setup.predictedAngles = std::move(*angles);
  for (int p = 0; p < setup.layout.projectors; ++p) {
    auto tables =
        buildTriangulationTables(rig, camera, p, options.depthUnitM, options.nominalDepthM);
    if (!tables) {
      return std::unexpected(tables.error());
    }
    setup.triangulation.push_back(std::move(*tables));
  }
  if (!(options.depthUnitM > 0.0) || !std::isfinite(options.depthUnitM)) {
    return std::unexpected("pipeline: the depth unit must be positive");
  }
  if (!(options.minDepthM >= 0.0) || !(options.maxDepthM > options.minDepthM) ||
      options.minConfidence < 1 || options.minConfidence > 255) {
    return std::unexpected(
        "pipeline: the depth window needs 0 <= min < max and a confidence of 1 to 255");
  }
  // Depths are whole units: keep every unit whose depth lies inside [min, max].
  const auto units = [&](double m) { return std::clamp(m / options.depthUnitM, 1.0, 65535.0); };
  setup.window = {.minUnits = static_cast<std::uint16_t>(std::ceil(units(options.minDepthM))),
                  .maxUnits = static_cast<std::uint16_t>(std::floor(units(options.maxDepthM))),
                  .minConfidence = static_cast<std::uint8_t>(options.minConfidence)};
  setup.trust = options.trust;
  setup.trust.tolerance.minUnits =
      static_cast<int>(std::clamp(std::ceil(kGrossToleranceM / options.depthUnitM), 1.0, 65535.0));
  // The working range: where the directions are predicted and a distorted projector's tables
  // are fitted (triangulation.hpp).
  setup.trust.nearUnits =
      static_cast<int>(std::ceil(units(kFitNearFactor * options.nominalDepthM)));
  setup.trust.farUnits =
      static_cast<int>(std::floor(units(kWorkingRangeFactor * options.nominalDepthM)));
  return setup;
}

}  // namespace smx::algo
