// The libcamera camera backend against the kernel's vimc driver (a virtual media-controller
// camera with a sensor, debayer and scaler), in a qemu guest (tests/kernel, libcamera-vimc).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "smx/linux/libcamera_open.hpp"

namespace smx::lnx {
namespace {

using hal::CameraFormat;
using hal::CameraState;
using hal::PixelFormat;

constexpr std::int64_t kSecondNs = 1'000'000'000;

// The size in "... the nearest it can is 636x480-BGR888".
CameraFormat suggestedFormat(const std::string& message) {
  CameraFormat format{0, 0, PixelFormat::kRgb24, 30};
  const auto at = message.find("nearest it can is ");
  if (at != std::string::npos) {
    std::sscanf(message.c_str() + at + 18, "%dx%d", &format.width, &format.height);
  }
  return format;
}

TEST(LibcameraVimc, StreamsFramesFromTheFirstCamera) {
  auto camera = openLibcameraCamera("", "cam0", 4);
  ASSERT_TRUE(camera) << camera.error();
  // vimc's scaler cannot make 640x480; the refusal names the nearest size it can, which works.
  auto refused = (*camera)->configure(CameraFormat{640, 480, PixelFormat::kRgb24, 30});
  ASSERT_FALSE(refused);
  const CameraFormat nearest = suggestedFormat(refused.error().message);
  ASSERT_GT(nearest.width, 0) << refused.error().message;
  std::printf("SMX-FIGURE: %s\n", refused.error().message);
  auto granted = (*camera)->configure(nearest);
  ASSERT_TRUE(granted) << granted.error().message;
  EXPECT_EQ(granted->width, nearest.width);
  EXPECT_EQ(granted->height, nearest.height);
  ASSERT_TRUE((*camera)->start());
  EXPECT_EQ((*camera)->state(), CameraState::kStreaming);

  std::uint64_t lastSequence = 0;
  std::int64_t lastStampNs = 0;
  constexpr int kFrames = 10;
  for (int i = 0; i < kFrames; ++i) {
    auto frame = (*camera)->acquire(10 * kSecondNs);
    ASSERT_TRUE(frame) << "frame " << i << ": " << frame.error().message;
    EXPECT_EQ(frame->image.width(), nearest.width);
    EXPECT_EQ(frame->image.height(), nearest.height);
    if (i > 0) {
      EXPECT_GT(frame->sequence, lastSequence);
      EXPECT_GT(frame->timestampNs, lastStampNs);
    }
    lastSequence = frame->sequence;
    lastStampNs = frame->timestampNs;
    // vimc's sensor shows colour bars: the frame is not one flat colour.
    int minGreen = 255;
    int maxGreen = 0;
    for (int x = 0; x < nearest.width; x += 8) {
      minGreen = std::min<int>(minGreen, frame->image(x, nearest.height / 2).g);
      maxGreen = std::max<int>(maxGreen, frame->image(x, nearest.height / 2).g);
    }
    EXPECT_GT(maxGreen - minGreen, 64) << "frame " << i;
    ASSERT_TRUE((*camera)->release(*frame));
  }
  EXPECT_TRUE((*camera)->stop());
  EXPECT_EQ((*camera)->state(), CameraState::kStopped);
}

TEST(LibcameraVimc, ACameraInUseIsRefusedWithItsName) {
  auto first = openLibcameraCamera("", "cam0", 4);
  ASSERT_TRUE(first) << first.error();
  auto second = openLibcameraCamera("", "cam1", 4);
  ASSERT_FALSE(second);
  EXPECT_NE(second.error().find("in use"), std::string::npos) << second.error();
}

TEST(LibcameraVimc, AnUnknownCameraIsRefusedListingTheCamerasSeen) {
  auto camera = openLibcameraCamera("no-such-sensor", "cam0", 4);
  ASSERT_FALSE(camera);
  EXPECT_NE(camera.error().find("Sensor B"), std::string::npos) << camera.error();
}

}  // namespace
}  // namespace smx::lnx
