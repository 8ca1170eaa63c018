#include "camera_images.hpp"

#include <optional>
#include <system_error>
#include <utility>

#include "smx/config/rig_json.hpp"

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
    for (const auto& earlier : out) {
      if (earlier.camera == *index) {
        std::string message = "--image " + spec;
        message += ": camera " + id;
        message += " already has an image (" + earlier.file.string();
        message += "); give one --image per camera";
        return std::unexpected(message);
      }
    }
    const std::filesystem::path file = spec.substr(eq + 1);
    std::error_code ec;
    const auto status = std::filesystem::status(file, ec);
    if (!std::filesystem::exists(status)) {
      return std::unexpected("--image " + spec + ": no such file");
    }
    // A FIFO or device would block the reader, maybe forever.
    if (!std::filesystem::is_regular_file(status)) {
      return std::unexpected("--image " + spec + ": not a regular file");
    }
    out.push_back({*index, file});
  }
  return out;
}

std::expected<void, std::string> checkHasColour(const std::filesystem::path& file,
                                                const sim::RgbImage& image) {
  for (const algo::Rgb8& p : image.pixels) {
    if (p.r != p.g || p.g != p.b) {
      return {};
    }
  }
  return std::unexpected(file.string() +
                         ": the image has no colour (every pixel is grey); stripemux decodes "
                         "colour stripes and needs the image of a colour camera");
}

std::expected<RigAndImages, std::string> loadRigAndImages(const std::filesystem::path& rigFile,
                                                          const std::vector<std::string>& specs) {
  auto rig = config::loadRig(rigFile);
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
