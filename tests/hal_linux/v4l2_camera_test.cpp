#include "smx/linux/v4l2_camera.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <filesystem>
#include <iterator>

#include "alloc_counter.hpp"
#include "fake_v4l2_driver.hpp"
#include "yuv_reference.hpp"

namespace smx::lnx {
namespace {

using hal::CameraFormat;
using hal::CameraFrame;
using hal::CameraState;
using hal::HalErrc;
using hal::PixelFormat;

CameraFrame frameOfBuffer(int index) {
  CameraFrame frame;
  frame.bufferIndex = index;
  return frame;
}

constexpr const char* kPath = "/dev/video7";
constexpr std::int64_t kTimeoutNs = 1'000'000;

// Writes a recognisable RGB24/BGR24 frame: byte i of row y is (y * 7 + i) & 255.
void fillRows(std::span<std::byte> memory, std::uint32_t stride, std::uint32_t rowBytes,
              std::uint32_t height) {
  for (std::uint32_t y = 0; y < height; ++y) {
    for (std::uint32_t i = 0; i < rowBytes; ++i) {
      memory[y * stride + i] = static_cast<std::byte>((y * 7 + i) & 0xFF);
    }
  }
}

class V4l2CameraTest : public testing::Test {
 protected:
  std::unique_ptr<V4l2Camera> open(int buffers = 4) {
    auto camera = V4l2Camera::create(kPath, "cam0", buffers, driver_);
    EXPECT_TRUE(camera) << camera.error();
    return camera ? std::move(*camera) : nullptr;
  }

  // A camera streaming 6x3 frames in `format`.
  std::unique_ptr<V4l2Camera> streaming(PixelFormat format, int buffers = 4) {
    auto camera = open(buffers);
    EXPECT_TRUE(camera->configure(CameraFormat{6, 3, format, 30}));
    EXPECT_TRUE(camera->start());
    return camera;
  }

  int produce(std::uint32_t flags = 0) {
    const v4l2_pix_format f = driver_.format();
    return driver_.produceFrame(
        [&](std::span<std::byte> memory) {
          fillRows(memory, f.bytesperline, f.bytesperline, f.height);
        },
        flags);
  }
  // A frame the driver stamps sec.usec (its flags say which end of the exposure that is).
  int produceStamped(std::int64_t sec, std::int64_t usec, std::uint32_t flags = 0) {
    driver_.setTimestamp(sec, usec);
    return produce(flags);
  }

  test::FakeV4l2Driver driver_;
};

TEST_F(V4l2CameraTest, CreateChecksCapabilitiesAndNamesTheDevice) {
  // Given an output-only device, then one without streaming I/O, then no device at all
  driver_.capabilities = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
  auto output = V4l2Camera::create(kPath, "cam0", 4, driver_);
  driver_.capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_READWRITE;
  auto readOnly = V4l2Camera::create(kPath, "cam0", 4, driver_);
  driver_.unplug();
  auto absent = V4l2Camera::create(kPath, "cam0", 4, driver_);
  // Then each fails with the device's path and the reason, and no descriptor leaks
  ASSERT_FALSE(output);
  EXPECT_NE(output.error().find(kPath), std::string::npos) << output.error();
  EXPECT_NE(output.error().find("not a video capture device"), std::string::npos);
  ASSERT_FALSE(readOnly);
  EXPECT_NE(readOnly.error().find("streaming"), std::string::npos) << readOnly.error();
  ASSERT_FALSE(absent);
  EXPECT_NE(absent.error().find(std::string("cannot open ") + kPath), std::string::npos)
      << absent.error();
  EXPECT_EQ(driver_.openFds(), 0);
}

TEST_F(V4l2CameraTest, CreateRejectsBufferCountsOutsideTwoToThirtyTwo) {
  EXPECT_FALSE(V4l2Camera::create(kPath, "cam0", 1, driver_));
  EXPECT_FALSE(V4l2Camera::create(kPath, "cam0", 33, driver_));
  EXPECT_TRUE(V4l2Camera::create(kPath, "cam0", 2, driver_));
}

TEST_F(V4l2CameraTest, ConfigureAcceptsAFormatTheDriverKeeps) {
  auto camera = open();
  EXPECT_EQ(camera->state(), CameraState::kUnconfigured);
  // When a supported size and format are asked for
  auto granted = camera->configure(CameraFormat{64, 48, PixelFormat::kYuyv, 30});
  // Then the driver got exactly that and the camera is stopped, ready to start
  ASSERT_TRUE(granted);
  EXPECT_EQ(granted->width, 64);
  EXPECT_EQ(granted->height, 48);
  EXPECT_EQ(granted->pixelFormat, PixelFormat::kYuyv);
  EXPECT_EQ(granted->fps, 30);
  EXPECT_EQ(driver_.format().pixelformat, V4L2_PIX_FMT_YUYV);
  EXPECT_EQ(driver_.format().width, 64U);
  EXPECT_EQ(camera->state(), CameraState::kStopped);
}

TEST_F(V4l2CameraTest, ConfigureRejectsASizeTheDriverChanges) {
  auto camera = open();
  // Given a driver that only has 640x480, 64x48 and 6x3
  auto granted = camera->configure(CameraFormat{1280, 720, PixelFormat::kRgb24, 30});
  ASSERT_FALSE(granted);
  EXPECT_EQ(granted.error().code, HalErrc::kNotSupported);
  EXPECT_EQ(camera->state(), CameraState::kUnconfigured);
  EXPECT_EQ(camera->start().error().code, HalErrc::kInvalidState);
}

TEST_F(V4l2CameraTest, ConfigureRejectsAPixelFormatTheDriverChanges) {
  driver_.pixelFormats = {V4L2_PIX_FMT_YUYV};
  auto camera = open();
  auto granted = camera->configure(CameraFormat{64, 48, PixelFormat::kRgb24, 30});
  ASSERT_FALSE(granted);
  EXPECT_EQ(granted.error().code, HalErrc::kNotSupported);
  // And the same camera then takes the format the driver has.
  EXPECT_TRUE(camera->configure(CameraFormat{64, 48, PixelFormat::kYuyv, 30}));
}

TEST_F(V4l2CameraTest, ConfigureRejectsOddYuyvWidthsAndNonPositiveValues) {
  auto camera = open();
  EXPECT_EQ(camera->configure(CameraFormat{5, 4, PixelFormat::kYuyv, 30}).error().code,
            HalErrc::kInvalidArgument);
  EXPECT_EQ(camera->configure(CameraFormat{6, 0, PixelFormat::kRgb24, 30}).error().code,
            HalErrc::kInvalidArgument);
  EXPECT_EQ(camera->configure(CameraFormat{6, 3, PixelFormat::kRgb24, 0}).error().code,
            HalErrc::kInvalidArgument);
  EXPECT_EQ(driver_.sFmtCalls(), 0);
}

TEST_F(V4l2CameraTest, ConfigureReportsTheFrameRateTheDriverGranted) {
  auto camera = open();
  // Given a driver limited to 15 fps, then one at NTSC's 30000/1001
  driver_.maxRate = {.numerator = 1, .denominator = 15};
  auto slow = camera->configure(CameraFormat{6, 3, PixelFormat::kRgb24, 30});
  driver_.maxRate = {.numerator = 1001, .denominator = 30000};
  auto ntsc = camera->configure(CameraFormat{6, 3, PixelFormat::kRgb24, 60});
  auto asked = camera->configure(CameraFormat{6, 3, PixelFormat::kRgb24, 25});
  ASSERT_TRUE(slow && ntsc && asked);
  EXPECT_EQ(slow->fps, 15);
  EXPECT_EQ(ntsc->fps, 30);
  EXPECT_EQ(asked->fps, 25);
}

TEST_F(V4l2CameraTest, ConfigureKeepsTheWantedRateWhenTheDriverHasNoRateControl) {
  driver_.sParmResult = -ENOTTY;
  auto camera = open();
  auto granted = camera->configure(CameraFormat{6, 3, PixelFormat::kRgb24, 24});
  ASSERT_TRUE(granted);
  EXPECT_EQ(granted->fps, 24);
}

TEST_F(V4l2CameraTest, CallsOutOfOrderAreInvalidState) {
  auto camera = open();
  EXPECT_EQ(camera->acquire(kTimeoutNs).error().code, HalErrc::kInvalidState);
  EXPECT_EQ(camera->start().error().code, HalErrc::kInvalidState);
  ASSERT_TRUE(camera->configure(CameraFormat{6, 3, PixelFormat::kRgb24, 30}));
  EXPECT_EQ(camera->acquire(kTimeoutNs).error().code, HalErrc::kInvalidState);
  EXPECT_EQ(camera->release(frameOfBuffer(0)).error().code, HalErrc::kInvalidState);
  ASSERT_TRUE(camera->start());
  EXPECT_EQ(camera->start().error().code, HalErrc::kInvalidState);
  EXPECT_EQ(camera->configure(CameraFormat{6, 3, PixelFormat::kRgb24, 30}).error().code,
            HalErrc::kInvalidState);
}

TEST_F(V4l2CameraTest, StartMapsAndQueuesEveryBufferAndStreams) {
  auto camera = streaming(PixelFormat::kRgb24, 3);
  EXPECT_EQ(camera->state(), CameraState::kStreaming);
  EXPECT_TRUE(driver_.streaming());
  EXPECT_EQ(driver_.bufferCount(), 3);
  EXPECT_EQ(driver_.mappedCount(), 3);
  EXPECT_EQ(driver_.queuedCount(), 3);
}

TEST_F(V4l2CameraTest, AcquireTimesOutWhenNoFrameCame) {
  auto camera = streaming(PixelFormat::kRgb24);
  EXPECT_EQ(camera->acquire(kTimeoutNs).error().code, HalErrc::kTimeout);
  EXPECT_EQ(camera->acquire(0).error().code, HalErrc::kTimeout);
  EXPECT_EQ(camera->state(), CameraState::kStreaming);
}

TEST_F(V4l2CameraTest, Rgb24FramesAreTheMappedBufferWithTheDriversStrideTimeAndSequence) {
  // Given rows padded to 18 + 5 bytes and a frame stamped 100.000250 s, sequence 41
  driver_.rowPaddingBytes = 5;
  auto camera = streaming(PixelFormat::kRgb24);
  driver_.setTimestamp(100, 250);
  driver_.setNextSequence(41);
  const int index = produce();
  // When acquired
  auto frame = camera->acquire(kTimeoutNs);
  // Then it is that buffer, in place, with the driver's metadata
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->bufferIndex, index);
  EXPECT_EQ(frame->sequence, 41U);
  EXPECT_EQ(frame->timestampNs, 100'000'250'000);
  EXPECT_EQ(frame->image.width(), 6);
  EXPECT_EQ(frame->image.height(), 3);
  EXPECT_EQ(frame->image.strideBytes(), 23);
  EXPECT_EQ(frame->image.bytes(), driver_.bufferMemory(index).data());
  // byte i of row y is y*7+i: pixel (2, 1) holds bytes 6, 7, 8 of row 1.
  EXPECT_EQ(frame->image(2, 1), (algo::Rgb8{13, 14, 15}));
  EXPECT_EQ(driver_.queuedCount(), 3);
  // When released, the buffer is queued again.
  ASSERT_TRUE(camera->release(*frame));
  EXPECT_EQ(driver_.queuedCount(), 4);
}

TEST_F(V4l2CameraTest, FramesExposedBeforeTheCallAreRequeuedAndTheNextOneIsReturned) {
  // Given a camera at 30 fps (33.3 ms a frame) called at t = 100 s, with two frames already
  // done: one ending at 99.9 s and one ending at 100.02 s, so exposed from 99.987 s (both before
  // the call), then one ending at 100.04 s (exposed from 100.007 s, after the call)
  auto camera = streaming(PixelFormat::kRgb24);
  driver_.setNowNs(100'000'000'000);
  produceStamped(99, 900'000);
  produceStamped(100, 20'000);
  const int fresh = produceStamped(100, 40'000);
  // When acquired
  auto frame = camera->acquire(kTimeoutNs);
  // Then the stale ones went back to the driver and the fresh one is returned
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->bufferIndex, fresh);
  EXPECT_EQ(frame->timestampNs, 100'040'000'000);
  EXPECT_EQ(camera->staleFrames(), 2U);
  EXPECT_EQ(driver_.queuedCount(), 3);
}

TEST_F(V4l2CameraTest, StartOfExposureStampsAreFreshFromTheCall) {
  auto camera = streaming(PixelFormat::kRgb24);
  driver_.setNowNs(100'000'000'000);
  produceStamped(99, 999'000);
  produceStamped(100, 1'000, V4L2_BUF_FLAG_TSTAMP_SRC_SOE);
  auto frame = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->timestampNs, 100'001'000'000);
  EXPECT_EQ(camera->staleFrames(), 1U);
}

TEST_F(V4l2CameraTest, Bgr24FramesAreConvertedIntoTheCamerasOwnBuffer) {
  auto camera = streaming(PixelFormat::kBgr24);
  const int index = produce();
  auto frame = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->bufferIndex, index);
  EXPECT_NE(frame->image.bytes(), driver_.bufferMemory(index).data());
  EXPECT_EQ(frame->image(2, 1), (algo::Rgb8{15, 14, 13}));
  EXPECT_EQ(frame->image(5, 2), (algo::Rgb8{31, 30, 29}));  // 14 + 15..17
}

TEST_F(V4l2CameraTest, YuyvFramesAreConvertedToRgb) {
  // Given a YUYV frame with padded rows: pair k of row y is Y0 = 40 + 30k + y, U = 90,
  // Y1 = Y0 + 10, V = 200
  driver_.rowPaddingBytes = 4;
  auto camera = streaming(PixelFormat::kYuyv);
  const std::uint32_t stride = driver_.format().bytesperline;
  ASSERT_EQ(stride, 16U);
  driver_.produceFrame([&](std::span<std::byte> memory) {
    for (std::uint32_t y = 0; y < 3; ++y) {
      for (std::uint32_t k = 0; k < 3; ++k) {
        std::byte* p = &memory[y * stride + 4 * k];
        p[0] = static_cast<std::byte>(40 + 30 * k + y);
        p[1] = std::byte{90};
        p[2] = static_cast<std::byte>(50 + 30 * k + y);
        p[3] = std::byte{200};
      }
    }
  });
  // When acquired
  auto frame = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(frame);
  // Then every pixel is the BT.601 reference within 1
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 6; ++x) {
      const int luma = 40 + 30 * (x / 2) + 10 * (x % 2) + y;
      const test::RgbDouble want = test::yuvToRgbExact(luma, 90, 200);
      const algo::Rgb8 got = frame->image(x, y);
      EXPECT_NEAR(got.r, test::roundClamp8(want.r), 1) << x << "," << y;
      EXPECT_NEAR(got.g, test::roundClamp8(want.g), 1) << x << "," << y;
      EXPECT_NEAR(got.b, test::roundClamp8(want.b), 1) << x << "," << y;
    }
  }
}

TEST_F(V4l2CameraTest, AcquireIsBusyWhileEveryBufferIsBorrowed) {
  // Given two buffers, both borrowed
  auto camera = streaming(PixelFormat::kRgb24, 2);
  produce();
  produce();
  auto first = camera->acquire(kTimeoutNs);
  auto second = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(first && second);
  EXPECT_NE(first->bufferIndex, second->bufferIndex);
  // Then the driver has nowhere to write and acquire() says so
  EXPECT_EQ(produce(), -1);
  EXPECT_EQ(camera->acquire(kTimeoutNs).error().code, HalErrc::kBusy);
  // When one is released, frames flow again, oldest buffer first
  ASSERT_TRUE(camera->release(*first));
  EXPECT_EQ(produce(), first->bufferIndex);
  auto third = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(third);
  EXPECT_EQ(third->bufferIndex, first->bufferIndex);
  // and the dropped frame shows in the sequence.
  EXPECT_EQ(third->sequence, second->sequence + 2);
}

TEST_F(V4l2CameraTest, ReleaseTwiceOrOfAFrameNeverHandedOutIsInvalidState) {
  auto camera = streaming(PixelFormat::kRgb24);
  produce();
  auto frame = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(frame);
  ASSERT_TRUE(camera->release(*frame));
  EXPECT_EQ(camera->release(*frame).error().code, HalErrc::kInvalidState);
  EXPECT_EQ(camera->release(frameOfBuffer(17)).error().code, HalErrc::kInvalidState);
  EXPECT_EQ(camera->release(CameraFrame{}).error().code, HalErrc::kInvalidState);
  // The driver saw one QBUF for it, not two.
  EXPECT_EQ(driver_.queuedCount(), 4);
}

TEST_F(V4l2CameraTest, FramesFromBeforeARestartCannotBeReleased) {
  auto camera = streaming(PixelFormat::kRgb24);
  produce();
  auto stale = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(stale);
  ASSERT_TRUE(camera->stop());
  EXPECT_EQ(camera->release(*stale).error().code, HalErrc::kInvalidState);
  ASSERT_TRUE(camera->start());
  driver_.setNextSequence(1000);
  produce();
  auto fresh = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(fresh);
  ASSERT_EQ(fresh->bufferIndex, stale->bufferIndex);
  EXPECT_EQ(camera->release(*stale).error().code, HalErrc::kInvalidState);
  EXPECT_TRUE(camera->release(*fresh));
}

TEST_F(V4l2CameraTest, StopUnmapsAndFreesTheBuffersAndMayBeRepeated) {
  auto camera = streaming(PixelFormat::kYuyv);
  produce();
  ASSERT_TRUE(camera->acquire(kTimeoutNs));  // stop() takes borrowed buffers back too
  ASSERT_TRUE(camera->stop());
  EXPECT_EQ(camera->state(), CameraState::kStopped);
  EXPECT_FALSE(driver_.streaming());
  EXPECT_EQ(driver_.mappedCount(), 0);
  EXPECT_EQ(driver_.bufferCount(), 0);  // REQBUFS 0 after the unmap (vb2 refuses it before)
  EXPECT_TRUE(camera->stop());
  EXPECT_EQ(camera->acquire(kTimeoutNs).error().code, HalErrc::kInvalidState);
  // And it can be reconfigured and started again.
  ASSERT_TRUE(camera->configure(CameraFormat{64, 48, PixelFormat::kRgb24, 30}));
  ASSERT_TRUE(camera->start());
  EXPECT_EQ(driver_.mappedCount(), 4);
}

TEST_F(V4l2CameraTest, DestructionStopsStreamingAndClosesTheDevice) {
  {
    auto camera = streaming(PixelFormat::kRgb24);
    EXPECT_EQ(driver_.openFds(), 1);
  }
  EXPECT_FALSE(driver_.streaming());
  EXPECT_EQ(driver_.mappedCount(), 0);
  EXPECT_EQ(driver_.openFds(), 0);
}

TEST_F(V4l2CameraTest, AReopenThatFailsAfterOpeningClosesTheDescriptor) {
  auto camera = streaming(PixelFormat::kRgb24);
  driver_.unplug();
  ASSERT_FALSE(camera->acquire(kTimeoutNs));
  // Given a device that comes back unable to capture
  driver_.capabilities = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
  driver_.plug();
  const int opensBefore = driver_.opens();
  // Then reopen opens it, refuses it and closes it again
  EXPECT_EQ(camera->reopen().error().code, HalErrc::kNotSupported);
  EXPECT_EQ(driver_.opens(), opensBefore + 1);
  EXPECT_EQ(driver_.openFds(), 0);
  EXPECT_TRUE(camera->lost());
}

// Descriptors of this process, counted from /proc/self/fd.
std::ptrdiff_t processFds() {
  return std::distance(std::filesystem::directory_iterator("/proc/self/fd"),
                       std::filesystem::directory_iterator{});
}

TEST(V4l2CameraSystemTest, ANonV4l2DeviceIsRefusedWithoutLeakingItsDescriptor) {
  // Given files that open but are no V4L2 devices, through the real system calls
  SystemV4l2Io io;
  const std::ptrdiff_t before = processFds();
  for (int i = 0; i < 3; ++i) {
    auto devNull = V4l2Camera::create("/dev/null", "cam0", 4, io);
    ASSERT_FALSE(devNull);
    EXPECT_NE(devNull.error().find("/dev/null is not a V4L2 device"), std::string::npos)
        << devNull.error();
  }
  // Then every descriptor opened on the way was closed
  EXPECT_EQ(processFds(), before);
}

TEST_F(V4l2CameraTest, CorruptAndShortFramesAreSkipped) {
  auto camera = streaming(PixelFormat::kRgb24);
  // Given a frame the driver flags as corrupt, a short one, then a good one
  driver_.produceRawFrame(driver_.format().sizeimage, V4L2_BUF_FLAG_ERROR);
  driver_.produceRawFrame(10);
  const int good = produce();
  // Then acquire returns the good one and counts the others
  auto frame = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->bufferIndex, good);
  EXPECT_EQ(frame->sequence, 2U);
  EXPECT_EQ(camera->corruptFrames(), 2U);
  EXPECT_EQ(driver_.queuedCount(), 3);  // the corrupt ones went straight back
}

TEST_F(V4l2CameraTest, SequenceNumbersContinuePastTheDriversThirtyTwoBits) {
  auto camera = streaming(PixelFormat::kRgb24);
  driver_.setNextSequence(0xFFFF'FFFE);
  std::uint64_t last = 0;
  for (int i = 0; i < 4; ++i) {
    produce();
    auto frame = camera->acquire(kTimeoutNs);
    ASSERT_TRUE(frame);
    last = frame->sequence;
    ASSERT_TRUE(camera->release(*frame));
  }
  EXPECT_EQ(last, 0x1'0000'0001U);
}

TEST_F(V4l2CameraTest, AnInterruptedPollIsRetried) {
  auto camera = streaming(PixelFormat::kRgb24);
  produce();
  driver_.pollEintrOnce = 2;
  EXPECT_TRUE(camera->acquire(kTimeoutNs));
}

TEST_F(V4l2CameraTest, UnplugWhileStreamingIsDisconnectedAndReopenRestoresStreaming) {
  auto camera = streaming(PixelFormat::kBgr24);
  produce();
  auto held = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(held);
  // When the device goes away
  driver_.unplug();
  auto gone = camera->acquire(kTimeoutNs);
  // Then acquire says so once, and every later call too, without touching the device
  ASSERT_FALSE(gone);
  EXPECT_EQ(gone.error().code, HalErrc::kDisconnected);
  EXPECT_TRUE(camera->lost());
  EXPECT_EQ(camera->disconnects(), 1U);
  EXPECT_EQ(camera->state(), CameraState::kStopped);
  EXPECT_EQ(driver_.openFds(), 0);
  EXPECT_EQ(camera->acquire(kTimeoutNs).error().code, HalErrc::kDisconnected);
  EXPECT_EQ(camera->start().error().code, HalErrc::kDisconnected);
  // A frame held across the loss is still readable and can be given back; the last one given
  // back unmaps the lost device's buffers, so that its driver can be unloaded.
  EXPECT_EQ(driver_.mappedCount(), 4);
  EXPECT_EQ(held->image(2, 1), (algo::Rgb8{15, 14, 13}));
  EXPECT_TRUE(camera->release(*held));
  EXPECT_EQ(driver_.mappedCount(), 0);
  // While the device is absent, reopen keeps failing
  EXPECT_EQ(camera->reopen().error().code, HalErrc::kDisconnected);
  // When it is back, reopen restores the format and streaming
  driver_.plug();
  ASSERT_TRUE(camera->reopen());
  EXPECT_FALSE(camera->lost());
  EXPECT_EQ(camera->state(), CameraState::kStreaming);
  EXPECT_EQ(driver_.format().pixelformat, V4L2_PIX_FMT_BGR24);
  EXPECT_EQ(driver_.format().width, 6U);
  EXPECT_TRUE(driver_.streaming());
  EXPECT_EQ(driver_.mappedCount(), 4);  // the old device's buffers were unmapped
  produce();
  auto frame = camera->acquire(kTimeoutNs);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->image(2, 1), (algo::Rgb8{15, 14, 13}));
}

// The fake driver with DQBUF failing as a driver being unbound does, while poll still reports
// a frame.
class DeadDequeue final : public V4l2Io {
 public:
  explicit DeadDequeue(V4l2Io& inner) : inner_(inner) {}
  int open(const char* path, int flags) override { return inner_.open(path, flags); }
  int close(int fd) override { return inner_.close(fd); }
  int ioctl(int fd, unsigned long request, void* arg) override {
    return request == VIDIOC_DQBUF ? -ENODEV : inner_.ioctl(fd, request, arg);
  }
  std::expected<void*, int> mmap(int fd, std::size_t length, std::int64_t offset) override {
    return inner_.mmap(fd, length, offset);
  }
  int munmap(void* address, std::size_t length) override { return inner_.munmap(address, length); }
  int poll(int fd, short events, std::int64_t timeoutNs, short& revents) override {
    return inner_.poll(fd, events, timeoutNs, revents);
  }
  std::int64_t nowNs() override { return inner_.nowNs(); }

 private:
  V4l2Io& inner_;
};

TEST_F(V4l2CameraTest, ALostDeviceWithNoFrameBorrowedIsUnmappedAtOnce) {
  auto camera = streaming(PixelFormat::kRgb24);
  driver_.unplug();
  EXPECT_EQ(camera->acquire(kTimeoutNs).error().code, HalErrc::kDisconnected);
  EXPECT_EQ(driver_.mappedCount(), 0);
  driver_.plug();
  ASSERT_TRUE(camera->reopen());
  EXPECT_EQ(driver_.mappedCount(), 4);
  EXPECT_EQ(camera->state(), CameraState::kStreaming);
}

TEST_F(V4l2CameraTest, DequeueFailingWithNoDeviceIsDisconnected) {
  DeadDequeue io(driver_);
  auto camera = V4l2Camera::create(kPath, "cam0", 2, io);
  ASSERT_TRUE(camera);
  ASSERT_TRUE((*camera)->configure(CameraFormat{6, 3, PixelFormat::kRgb24, 30}));
  ASSERT_TRUE((*camera)->start());
  produce();
  auto frame = (*camera)->acquire(kTimeoutNs);
  ASSERT_FALSE(frame);
  EXPECT_EQ(frame.error().code, HalErrc::kDisconnected);
  EXPECT_EQ(frame.error().sysErrno, ENODEV);
  EXPECT_TRUE((*camera)->lost());
  EXPECT_EQ(driver_.openFds(), 0);
}

TEST_F(V4l2CameraTest, ConfigureWhileAnotherUserHoldsTheBuffersIsBusy) {
  auto first = streaming(PixelFormat::kRgb24);
  auto second = open();
  EXPECT_EQ(second->configure(CameraFormat{6, 3, PixelFormat::kRgb24, 30}).error().code,
            HalErrc::kBusy);
  ASSERT_TRUE(first->stop());
  EXPECT_TRUE(second->configure(CameraFormat{6, 3, PixelFormat::kRgb24, 30}));
}

v4l2_queryctrl control(std::uint32_t id, std::int32_t minimum, std::int32_t maximum,
                       std::int32_t defaultValue) {
  v4l2_queryctrl query{};
  query.id = id;
  query.minimum = minimum;
  query.maximum = maximum;
  query.default_value = defaultValue;
  query.step = 1;
  return query;
}

// A UVC-like camera: auto exposure (menu, default aperture priority), exposure in 100 µs units,
// gain whose default (32) is unity.
TEST_F(V4l2CameraTest, ExposureAndGainAreSetInTheDriversUnitsAndRestoredOnReopen) {
  driver_.controls[V4L2_CID_EXPOSURE_AUTO] =
      control(V4L2_CID_EXPOSURE_AUTO, 0, 3, V4L2_EXPOSURE_APERTURE_PRIORITY);
  driver_.controls[V4L2_CID_EXPOSURE_ABSOLUTE] = control(V4L2_CID_EXPOSURE_ABSOLUTE, 3, 2047, 156);
  driver_.controls[V4L2_CID_GAIN] = control(V4L2_CID_GAIN, 0, 255, 32);
  auto camera = streaming(PixelFormat::kRgb24);
  EXPECT_TRUE(camera->controlSupport().exposure);
  EXPECT_TRUE(camera->controlSupport().gain);

  ASSERT_TRUE(camera->setControls({.exposureUs = 20'000, .gain = 2.5}));
  EXPECT_EQ(driver_.controlValues[V4L2_CID_EXPOSURE_AUTO], V4L2_EXPOSURE_MANUAL);
  EXPECT_EQ(driver_.controlValues[V4L2_CID_EXPOSURE_ABSOLUTE], 200);
  EXPECT_EQ(driver_.controlValues[V4L2_CID_GAIN], 80);

  // Beyond the control's range: refused, and what was set stays.
  const auto tooLong = camera->setControls({.exposureUs = 300'000, .gain = std::nullopt});
  ASSERT_FALSE(tooLong);
  EXPECT_EQ(tooLong.error().code, HalErrc::kInvalidArgument);
  EXPECT_EQ(driver_.controlValues[V4L2_CID_GAIN], 80);

  // A replugged device starts with its defaults: reopen() sets the controls again.
  driver_.unplug();
  (void)camera->acquire(kTimeoutNs);
  driver_.plug();
  driver_.controlValues.clear();
  ASSERT_TRUE(camera->reopen());
  EXPECT_EQ(driver_.controlValues[V4L2_CID_EXPOSURE_ABSOLUTE], 200);
  EXPECT_EQ(driver_.controlValues[V4L2_CID_GAIN], 80);

  // Nothing set: the driver's defaults, automatic exposure again.
  ASSERT_TRUE(camera->setControls({}));
  EXPECT_EQ(driver_.controlValues[V4L2_CID_EXPOSURE_AUTO], V4L2_EXPOSURE_APERTURE_PRIORITY);
  EXPECT_EQ(driver_.controlValues[V4L2_CID_EXPOSURE_ABSOLUTE], 156);
  EXPECT_EQ(driver_.controlValues[V4L2_CID_GAIN], 32);
}

TEST_F(V4l2CameraTest, ACameraWithoutControlsRefusesExposureAndGain) {
  auto camera = streaming(PixelFormat::kRgb24);
  EXPECT_FALSE(camera->controlSupport().exposure);
  EXPECT_FALSE(camera->controlSupport().gain);
  const auto refused = camera->setControls({.exposureUs = 5000, .gain = std::nullopt});
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, HalErrc::kNotSupported);
  EXPECT_TRUE(camera->setControls({}));
  EXPECT_TRUE(driver_.controlValues.empty());
}

TEST_F(V4l2CameraTest, SteadyStateAcquireAndReleaseNeverAllocate) {
  for (const PixelFormat format : {PixelFormat::kRgb24, PixelFormat::kBgr24, PixelFormat::kYuyv}) {
    auto camera = streaming(format);
    // Warm-up: one frame through (the fake's queues are reserved at REQBUFS).
    produce();
    auto warm = camera->acquire(kTimeoutNs);
    ASSERT_TRUE(warm);
    ASSERT_TRUE(camera->release(*warm));
    const test::AllocationCounter counter;
    for (int i = 0; i < 100; ++i) {
      produce();
      auto frame = camera->acquire(kTimeoutNs);
      ASSERT_TRUE(frame);
      ASSERT_TRUE(camera->release(*frame));
      ASSERT_EQ(camera->acquire(0).error().code, HalErrc::kTimeout);
    }
    EXPECT_EQ(counter.allocations(), 0U) << toString(format);
    ASSERT_TRUE(camera->stop());
  }
}

}  // namespace
}  // namespace smx::lnx
