#include "smx/health/camera_depths.hpp"

#include <cstddef>

#include "smx/algo/arena.hpp"

namespace smx::health {

std::expected<CameraDepths, std::string> decodeCameraDepths(const algo::Rig& rig, int camera,
                                                            algo::ConstRgbView image,
                                                            const algo::PipelineOptions& options) {
  const algo::Camera& cam = rig.cameras.at(static_cast<std::size_t>(camera));
  if (image.width() != cam.width || image.height() != cam.height) {
    return std::unexpected(cam.id + ": the image is " + std::to_string(image.width()) + "x" +
                           std::to_string(image.height()) + ", the rig says " +
                           std::to_string(cam.width) + "x" + std::to_string(cam.height));
  }
  const auto setup = algo::prepareCameraPipeline(rig, camera, options);
  if (!setup) {
    return std::unexpected(cam.id + ": " + setup.error());
  }
  const auto bytes = algo::CameraPipeline::workspaceBytes(*setup);
  if (!bytes) {
    return std::unexpected(cam.id + ": " + bytes.error().message);
  }
  std::vector<std::byte> memory(*bytes);
  algo::Arena arena(memory);
  auto pipeline = algo::CameraPipeline::create(*setup, arena);
  if (!pipeline) {
    return std::unexpected(cam.id + ": " + pipeline.error().message);
  }
  if (auto ok = pipeline->run(image); !ok) {
    return std::unexpected(cam.id + ": " + ok.error().message);
  }
  CameraDepths out;
  out.camera = camera;
  out.width = cam.width;
  out.height = cam.height;
  out.depthUnitM = options.depthUnitM;
  for (int p = 0; p < pipeline->projectors(); ++p) {
    const algo::ConstDepthPlane depth = pipeline->depth(p);
    const algo::ConstStripePlane stripe = pipeline->stripe(p);
    auto& d = out.depth.emplace_back(static_cast<std::size_t>(cam.width) *
                                     static_cast<std::size_t>(cam.height));
    auto& s = out.stripe.emplace_back(d.size());
    for (int y = 0; y < cam.height; ++y) {
      for (int x = 0; x < cam.width; ++x) {
        d[out.index(x, y)] = depth(x, y);
        s[out.index(x, y)] = stripe(x, y);
      }
    }
  }
  return out;
}

}  // namespace smx::health
