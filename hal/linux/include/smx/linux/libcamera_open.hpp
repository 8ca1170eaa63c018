#pragma once

#include <expected>
#include <memory>
#include <string>
#include <string_view>

#include "smx/hal/camera.hpp"

// Cameras behind libcamera (CSI sensors with an ISP, e.g. the Raspberry Pi camera modules), named
// "libcamera:<id>" in board.json (the libcamera camera id; "libcamera:" alone takes the first).
// CMake compiles libcamera_camera.cpp when libcamera is found and libcamera_absent.cpp otherwise
// (the board build today): the choice is the build's, not an #if.
namespace smx::lnx {

inline constexpr std::string_view kLibcameraPrefix = "libcamera:";

[[nodiscard]] bool libcameraBuilt();

// Opens the camera (init time); the error names it and lists the cameras libcamera sees.
[[nodiscard]] std::expected<std::unique_ptr<hal::Camera>, std::string> openLibcameraCamera(
    std::string_view name, std::string_view cameraId, int buffers);

}  // namespace smx::lnx
