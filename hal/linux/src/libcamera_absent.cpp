#include "smx/linux/libcamera_open.hpp"

namespace smx::lnx {

bool libcameraBuilt() {
  return false;
}

std::expected<std::unique_ptr<hal::Camera>, std::string> openLibcameraCamera(
    std::string_view name, std::string_view /*cameraId*/, int /*buffers*/) {
  return std::unexpected("'" + std::string(kLibcameraPrefix) + std::string(name) +
                         "': this stripemuxd was built without libcamera (install libcamera-dev "
                         "for the target and rebuild), or name a V4L2 device (/dev/videoN)");
}

}  // namespace smx::lnx
