#pragma once

#include <cstddef>
#include <expected>
#include <filesystem>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/sim/png_io.hpp"

// `--image CAM=FILE` arguments shared by the commands that take camera images.
namespace smx::host {

struct CameraImage {
  std::size_t camera;  // index into rig.cameras
  std::filesystem::path file;
};

// Each spec must be CAMERA=FILE with a camera id of the rig, one per camera, and FILE a regular
// file; errors name the spec and list the rig's cameras.
[[nodiscard]] std::expected<std::vector<CameraImage>, std::string> parseCameraImages(
    const std::vector<std::string>& specs, const algo::Rig& rig);

// The rig file and the `--image` specs of a command, checked together.
struct RigAndImages {
  algo::Rig rig;
  std::vector<CameraImage> images;
};
[[nodiscard]] std::expected<RigAndImages, std::string> loadRigAndImages(
    const std::filesystem::path& rigFile, const std::vector<std::string>& specs);

// Reads the PNG and checks it has the camera's size; errors name the file.
[[nodiscard]] std::expected<sim::RgbImage, std::string> readCameraImage(
    const std::filesystem::path& file, const algo::Camera& camera);

// An image whose pixels are all grey holds no stripe colours: an error naming the file that says
// so, rather than "0 depth pixels".
[[nodiscard]] std::expected<void, std::string> checkHasColour(const std::filesystem::path& file,
                                                              const sim::RgbImage& image);

}  // namespace smx::host
