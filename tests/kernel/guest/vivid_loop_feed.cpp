// Feeds a rendered camera image to vivid's capture input through the driver's video loop (its
// HDMI output looped back to its HDMI input), so that the firmware in the guest captures a real
// scene through the real V4L2 capture path. Runs until killed.
//
//   vivid_loop_feed CAPTURE_DEV OUTPUT_DEV IMAGE.ppm
//
// vivid loops only when both sides have the same size, pixel format and field order and are
// HDMI (kernel doc admin-guide/media/vivid, "Video looping"). The capture device's format is
// set by the camera that opens it; this sets the timings both sides share, turns off vivid's
// on-screen text and turns the loop on.
#include <fcntl.h>
#include <linux/v4l2-dv-timings.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "ppm_io.hpp"

namespace {

namespace algo = smx::algo;

// vivid's private controls (drivers/media/test-drivers/vivid/vivid-ctrls.c).
constexpr std::uint32_t kVividBase = 0x00f00000 | 0xf000;
constexpr std::uint32_t kOsdTextMode = kVividBase + 1;  // 2: none
constexpr std::uint32_t kLoopVideo = kVividBase + 37;
constexpr int kWidth = 640;
constexpr int kHeight = 480;

// Caught in main(), which reports it and exits 1.
[[noreturn]] void fail(const std::string& what) {
  throw std::runtime_error(what + ": " + std::error_code(errno, std::generic_category()).message());
}

void xioctl(int fd, unsigned long request, void* arg, const char* name) {
  while (::ioctl(fd, request, arg) < 0) {
    if (errno != EINTR) {
      fail(name);
    }
  }
}

// The frame to loop, which must be kWidth x kHeight.
std::vector<algo::Rgb8> readFrame(const char* path) {
  auto image = smx::test::readPpm(path);
  if (!image) {
    throw std::runtime_error(image.error());
  }
  if (image->width != kWidth || image->height != kHeight) {
    throw std::runtime_error(std::string(path) + " is not 640x480");
  }
  return std::move(image->pixels);
}

void setTimings(int fd, const char* side) {
  v4l2_dv_timings timings = V4L2_DV_BT_CEA_640X480P59_94;
  xioctl(fd, VIDIOC_S_DV_TIMINGS, &timings, side);
}

void setControl(int fd, std::uint32_t id, int value, const char* name) {
  v4l2_control control{.id = id, .value = value};
  xioctl(fd, VIDIOC_S_CTRL, &control, name);
}

}  // namespace

namespace {

[[noreturn]] void feed(const char* captureDevice, const char* outputDevice, const char* ppm);

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: vivid_loop_feed CAPTURE_DEV OUTPUT_DEV IMAGE.ppm\n");
    return 2;
  }
  try {
    feed(argv[1], argv[2], argv[3]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vivid_loop_feed: %s\n", e.what());
    return 1;
  }
}

namespace {

void feed(const char* captureDevice, const char* outputDevice, const char* ppm) {
  const std::vector<algo::Rgb8> image = readFrame(ppm);

  const int capture = ::open(captureDevice, O_RDWR);
  if (capture < 0) {
    fail(captureDevice);
  }
  setTimings(capture, "capture VIDIOC_S_DV_TIMINGS");
  setControl(capture, kOsdTextMode, 2, "OSD text mode");
  setControl(capture, kLoopVideo, 1, "loop video");

  const int output = ::open(outputDevice, O_RDWR);
  if (output < 0) {
    fail(outputDevice);
  }
  setTimings(output, "output VIDIOC_S_DV_TIMINGS");
  v4l2_format format{};
  format.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  format.fmt.pix.width = kWidth;
  format.fmt.pix.height = kHeight;
  format.fmt.pix.pixelformat = V4L2_PIX_FMT_RGB24;
  format.fmt.pix.field = V4L2_FIELD_NONE;
  xioctl(output, VIDIOC_S_FMT, &format, "output VIDIOC_S_FMT");
  if (format.fmt.pix.width != kWidth || format.fmt.pix.height != kHeight ||
      format.fmt.pix.pixelformat != V4L2_PIX_FMT_RGB24) {
    errno = EINVAL;
    fail("the output refused 640x480 RGB24");
  }
  const std::size_t stride = format.fmt.pix.bytesperline;

  v4l2_requestbuffers request{};
  request.count = 2;
  request.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  request.memory = V4L2_MEMORY_MMAP;
  xioctl(output, VIDIOC_REQBUFS, &request, "output VIDIOC_REQBUFS");
  for (std::uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer{};
    buffer.index = i;
    buffer.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    buffer.memory = V4L2_MEMORY_MMAP;
    xioctl(output, VIDIOC_QUERYBUF, &buffer, "output VIDIOC_QUERYBUF");
    void* mapped =
        ::mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, output, buffer.m.offset);
    if (mapped == MAP_FAILED) {
      fail("output mmap");
    }
    auto* bytes = static_cast<char*>(mapped);
    constexpr std::size_t kRowBytes = static_cast<std::size_t>(kWidth) * 3;
    for (std::size_t y = 0; y < kHeight; ++y) {
      std::memcpy(bytes + y * stride, image.data() + y * kWidth, kRowBytes);
    }
    buffer.bytesused = static_cast<std::uint32_t>(stride * kHeight);
    xioctl(output, VIDIOC_QBUF, &buffer, "output VIDIOC_QBUF");
  }
  int type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  xioctl(output, VIDIOC_STREAMON, &type, "output VIDIOC_STREAMON");
  std::printf("vivid_loop_feed: looping %s into %s\n", ppm, captureDevice);
  std::fflush(stdout);
  // The same picture, again and again: each buffer goes back as soon as the driver shows it.
  for (;;) {
    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    buffer.memory = V4L2_MEMORY_MMAP;
    xioctl(output, VIDIOC_DQBUF, &buffer, "output VIDIOC_DQBUF");
    xioctl(output, VIDIOC_QBUF, &buffer, "output VIDIOC_QBUF");
  }
}

}  // namespace
