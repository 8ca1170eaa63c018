#include "camera_images.hpp"

#include <optional>
#include <utility>

#include "smx/protocol/rig_json.hpp"

namespace smx::host {

std::expected<std::vector<CameraImage>, std::string> parseCameraImages(
    const std::vector<std::string>& specs, const algo::Rig& rig) {
  std::vector<CameraImage> out;
  for (const auto& spec : specs) {
    const auto eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size()) {
      return std::unexpected("--image " + spec + ": expected CAMERA=FILE, e.g. cam0=frame.png");
    }
    const std::string id = spec.substr(0, eq);
    std::optional<std::size_t> index;
    std::string known;
    for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
      index = rig.cameras[c].id == id ? std::optional(c) : index;
      known += (known.empty() ? "" : ", ") + rig.cameras[c].id;
    }
    if (!index) {
      std::string message = "--image " + spec;
      message += ": the rig has no camera \"";
      message += id;
      message += "\" (cameras: ";
      message += known;
      message += ")";
      return std::unexpected(message);
    }
    out.push_back({*index, spec.substr(eq + 1)});
  }
  return out;
}

std::expected<RigAndImages, std::string> loadRigAndImages(const std::filesystem::path& rigFile,
                                                          const std::vector<std::string>& specs) {
  auto rig = protocol::loadRig(rigFile);
  if (!rig) {
    return std::unexpected(rig.error().message());
  }
  auto images = parseCameraImages(specs, *rig);
  if (!images) {
    return std::unexpected(images.error());
  }
  return RigAndImages{std::move(*rig), std::move(*images)};
}

std::expected<sim::RgbImage, std::string> readCameraImage(const std::filesystem::path& file,
                                                          const algo::Camera& camera) {
  // The camera's size is checked against the file's header, before the pixels are allocated.
  const std::string owner = "camera " + camera.id;
  return sim::readPngRgb8(file, sim::PngSizeLimit::exactly(camera.width, camera.height, owner));
}

}  // namespace smx::host
