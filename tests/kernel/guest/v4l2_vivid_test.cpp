// The V4L2 camera backend against the kernel's vivid driver, in a qemu guest (tests/kernel,
// v4l2-vivid). vivid's webcam input shows colour bars; the guest loaded it with one capture node.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <thread>

#include "smx/linux/v4l2_camera.hpp"
#include "smx/linux/v4l2_io.hpp"

namespace smx::lnx {
namespace {

using hal::CameraFormat;
using hal::CameraState;
using hal::HalErrc;
using hal::PixelFormat;

constexpr const char* kDevice = "/dev/video0";
constexpr std::int64_t kSecondNs = 1'000'000'000;
// vivid's "Disconnect" control: acts as an unplugged USB camera (vivid-ctrls.c).
constexpr std::uint32_t kVividDisconnect = (0x00f00000 | 0xf000) + 65;

struct Streaming {
  std::unique_ptr<V4l2Camera> camera;
  CameraFormat granted;
};

Streaming startCamera(V4l2Io& io, PixelFormat format, int fps) {
  auto camera = V4l2Camera::create(kDevice, "cam0", 4, io);
  EXPECT_TRUE(camera) << (camera ? "" : camera.error());
  if (!camera) {
    return {};
  }
  auto granted = (*camera)->configure(CameraFormat{640, 480, format, fps});
  EXPECT_TRUE(granted) << (granted ? "" : granted.error().message);
  EXPECT_TRUE((*camera)->start());
  return {std::move(*camera), granted.value_or(CameraFormat{})};
}

// The mean colour of a 16x16 patch centred on (x, y).
algo::Rgb8 meanColour(const algo::ConstRgbView& image, int x, int y) {
  int sum[3] = {0, 0, 0};
  for (int dy = -8; dy < 8; ++dy) {
    for (int dx = -8; dx < 8; ++dx) {
      const algo::Rgb8 p = image(x + dx, y + dy);
      sum[0] += p.r;
      sum[1] += p.g;
      sum[2] += p.b;
    }
  }
  return {static_cast<std::uint8_t>(sum[0] / 256), static_cast<std::uint8_t>(sum[1] / 256),
          static_cast<std::uint8_t>(sum[2] / 256)};
}

// The centre of each of vivid's eight colour bars, halfway down (below its on-screen text).
std::vector<algo::Rgb8> barColours(const algo::ConstRgbView& image) {
  std::vector<algo::Rgb8> bars;
  bars.reserve(8);
  for (int bar = 0; bar < 8; ++bar) {
    bars.push_back(meanColour(image, bar * 80 + 40, 300));
  }
  return bars;
}

TEST(V4l2Vivid, NegotiatesRgb24AndYuyvAt640x480AndBothShowTheSameColourBars) {
  SystemV4l2Io io;
  std::vector<algo::Rgb8> seen[2];
  int i = 0;
  for (const PixelFormat format : {PixelFormat::kRgb24, PixelFormat::kYuyv}) {
    auto stream = startCamera(io, format, 25);
    ASSERT_TRUE(stream.camera);
    EXPECT_EQ(stream.granted.width, 640);
    EXPECT_EQ(stream.granted.height, 480);
    EXPECT_EQ(stream.granted.pixelFormat, format);
    auto frame = stream.camera->acquire(5 * kSecondNs);
    ASSERT_TRUE(frame) << frame.error().message;
    EXPECT_EQ(frame->image.width(), 640);
    EXPECT_EQ(frame->image.height(), 480);
    seen[i++] = barColours(frame->image);
    ASSERT_TRUE(stream.camera->release(*frame));
  }
  // 75 % colour bars: white, yellow, cyan, green, magenta, red, blue, black.
  const int expected[8][3] = {{1, 1, 1}, {1, 1, 0}, {0, 1, 1}, {0, 1, 0},
                              {1, 0, 1}, {1, 0, 0}, {0, 0, 1}, {0, 0, 0}};
  for (int bar = 0; bar < 8; ++bar) {
    const algo::Rgb8 rgb = seen[0][static_cast<std::size_t>(bar)];
    const algo::Rgb8 yuv = seen[1][static_cast<std::size_t>(bar)];
    const int rgbChannels[3] = {rgb.r, rgb.g, rgb.b};
    const int yuvChannels[3] = {yuv.r, yuv.g, yuv.b};
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(rgbChannels[c] > 128 ? 1 : 0, expected[bar][c])
          << "bar " << bar << " channel " << c;
      // The driver's YUYV, converted by pixel_convert, against its own RGB24.
      EXPECT_NEAR(yuvChannels[c], rgbChannels[c], 4) << "bar " << bar << " channel " << c;
    }
  }
}

TEST(V4l2Vivid, Streams100FramesAtTheRequestedRate) {
  SystemV4l2Io io;
  auto stream = startCamera(io, PixelFormat::kRgb24, 25);
  ASSERT_TRUE(stream.camera);
  EXPECT_EQ(stream.granted.fps, 25);
  std::uint64_t firstSequence = 0;
  std::int64_t firstStampNs = 0;
  std::uint64_t lastSequence = 0;
  std::int64_t lastStampNs = 0;
  const auto start = std::chrono::steady_clock::now();
  constexpr int kFrames = 100;
  for (int i = 0; i < kFrames; ++i) {
    auto frame = stream.camera->acquire(2 * kSecondNs);
    ASSERT_TRUE(frame) << "frame " << i << ": " << frame.error().message;
    if (i == 0) {
      firstSequence = frame->sequence;
      firstStampNs = frame->timestampNs;
    } else {
      EXPECT_GT(frame->sequence, lastSequence);
      EXPECT_GT(frame->timestampNs, lastStampNs);
    }
    lastSequence = frame->sequence;
    lastStampNs = frame->timestampNs;
    ASSERT_TRUE(stream.camera->release(*frame));
  }
  const double seconds = static_cast<double>(lastStampNs - firstStampNs) / 1e9;
  const double driverFps = static_cast<double>(lastSequence - firstSequence) / seconds;
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "SMX-FIGURE: vivid 640x480 RGB24 driver %.2f fps, acquired %.2f fps (%d frames), "
      "stale skipped %llu, corrupt %llu\n",
      driverFps, kFrames / wall, kFrames,
      static_cast<unsigned long long>(stream.camera->staleFrames()),
      static_cast<unsigned long long>(stream.camera->corruptFrames()));
  // The driver runs at the rate asked for (its own time stamps and sequence numbers). The rate
  // acquired is a figure, not a check: each frame must begin after its call, so at most every
  // other frame is handed out.
  EXPECT_NEAR(driverFps, 25.0, 1.5);
}

TEST(V4l2Vivid, ADequeueTimeoutLeavesTheCameraStreaming) {
  SystemV4l2Io io;
  auto stream = startCamera(io, PixelFormat::kRgb24, 25);
  ASSERT_TRUE(stream.camera);
  // A frame takes 40 ms; none can begin and end within 1 ms of the call.
  auto none = stream.camera->acquire(1'000'000);
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error().code, HalErrc::kTimeout);
  EXPECT_EQ(stream.camera->state(), CameraState::kStreaming);
  auto frame = stream.camera->acquire(2 * kSecondNs);
  ASSERT_TRUE(frame) << frame.error().message;
  EXPECT_TRUE(stream.camera->release(*frame));
}

void disconnectVivid() {
  const int fd = ::open(kDevice, O_RDWR);
  ASSERT_GE(fd, 0);
  v4l2_control control{.id = kVividDisconnect, .value = 0};
  ASSERT_EQ(::ioctl(fd, VIDIOC_S_CTRL, &control), 0)
      << std::error_code(errno, std::generic_category()).message();
  ::close(fd);
}

bool waitForDevice(bool present) {
  for (int i = 0; i < 200; ++i) {
    if (std::filesystem::exists(kDevice) == present) {
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

TEST(V4l2Vivid, RecoversWhenTheDriverIsUnloadedAndReloaded) {
  SystemV4l2Io io;
  auto stream = startCamera(io, PixelFormat::kYuyv, 25);
  ASSERT_TRUE(stream.camera);
  auto before = stream.camera->acquire(2 * kSecondNs);
  ASSERT_TRUE(before);
  ASSERT_TRUE(stream.camera->release(*before));

  // Unplugged: the next acquire notices, and the camera lets go of the device.
  disconnectVivid();
  auto lost = stream.camera->acquire(2 * kSecondNs);
  ASSERT_FALSE(lost);
  EXPECT_EQ(lost.error().code, HalErrc::kDisconnected);
  EXPECT_TRUE(stream.camera->lost());

  // With nothing holding it, the driver can go; the camera cannot come back while it is gone.
  ASSERT_EQ(std::system("rmmod vivid"), 0);  // NOLINT(concurrency-mt-unsafe): one thread
  ASSERT_TRUE(waitForDevice(false));
  auto absent = stream.camera->reopen();
  ASSERT_FALSE(absent);
  EXPECT_EQ(absent.error().code, HalErrc::kDisconnected);

  ASSERT_EQ(std::system("modprobe vivid"), 0);  // NOLINT(concurrency-mt-unsafe): one thread
  ASSERT_TRUE(waitForDevice(true));
  auto reopened = stream.camera->reopen();
  ASSERT_TRUE(reopened) << reopened.error().message;
  EXPECT_EQ(stream.camera->state(), CameraState::kStreaming);
  auto after = stream.camera->acquire(2 * kSecondNs);
  ASSERT_TRUE(after) << after.error().message;
  EXPECT_EQ(after->image.width(), 640);
  EXPECT_EQ(stream.camera->disconnects(), 1U);
  EXPECT_TRUE(stream.camera->release(*after));
}

}  // namespace
}  // namespace smx::lnx
