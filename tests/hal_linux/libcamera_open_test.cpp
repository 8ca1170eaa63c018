#include "smx/linux/libcamera_open.hpp"

#include <gtest/gtest.h>

#include <string>

namespace smx::lnx {
namespace {

// Without a camera: a name libcamera does not know is refused with the device named, in builds
// with libcamera (it also lists what libcamera sees) and without (it says what to do).
TEST(LibcameraOpen, AnUnknownCameraIsRefusedWithItsName) {
  const auto camera = openLibcameraCamera("no-such-camera", "cam0", 4);
  ASSERT_FALSE(camera.has_value());
  const std::string& message = camera.error();
  EXPECT_NE(message.find("'libcamera:no-such-camera'"), std::string::npos) << message;
  if (libcameraBuilt()) {
    const bool listed = message.find("no such camera (libcamera sees") != std::string::npos;
    const bool noManager = message.find("libcamera cannot start") != std::string::npos;
    EXPECT_TRUE(listed || noManager) << message;
  } else {
    EXPECT_NE(message.find("built without libcamera"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace smx::lnx
