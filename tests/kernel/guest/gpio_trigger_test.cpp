// The firmware's trigger lines on the kernel's gpio-sim, in a qemu guest (tests/kernel,
// gpio-sim): the qemu board (boards/qemu) drives gpio-sim lines 0 and 1 around each capture of
// its vivid camera, and a sampler reads the lines back from gpio-sim's sysfs values.
//
// Environment: SMX_BOARD (the board folder), SMX_GPIO_SIM (gpio-sim's sysfs folder of the
// chip, holding sim_gpio<N>/value).
#include <fcntl.h>
#include <gpiod.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <thread>
#include <vector>

#include "smx/config/board_json.hpp"
#include "smx/device/device.hpp"
#include "smx/hal/board_hal.hpp"

namespace smx {
namespace {

std::int64_t monotonicNs() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

std::string env(const char* name) {
  const char* value = std::getenv(name);  // NOLINT(concurrency-mt-unsafe): read before threads
  return value != nullptr ? value : "";
}

// Forwards to the board's camera and keeps what the device was given.
class RecordingCamera final : public hal::Camera {
 public:
  explicit RecordingCamera(hal::Camera& inner) : inner_(inner) {
    stampsNs.reserve(64);
    deliveredNs.reserve(64);
  }
  hal::HalResult<hal::CameraFormat> configure(const hal::CameraFormat& wanted) override {
    auto granted = inner_.configure(wanted);
    if (granted) {
      format = *granted;
    }
    return granted;
  }
  hal::HalResult<void> start() override { return inner_.start(); }
  hal::HalResult<void> stop() override { return inner_.stop(); }
  hal::HalResult<hal::CameraFrame> acquire(std::int64_t timeoutNs) override {
    auto frame = inner_.acquire(timeoutNs);
    if (frame) {
      stampsNs.push_back(frame->timestampNs);
      deliveredNs.push_back(monotonicNs());
    }
    return frame;
  }
  hal::HalResult<void> release(const hal::CameraFrame& frame) override {
    return inner_.release(frame);
  }
  hal::CameraState state() const override { return inner_.state(); }
  std::string_view id() const override { return inner_.id(); }

  hal::CameraFormat format;
  std::vector<std::int64_t> stampsNs;     // the driver's end-of-frame stamps
  std::vector<std::int64_t> deliveredNs;  // when acquire() returned the frame

 private:
  hal::Camera& inner_;
};

struct Sample {
  std::int64_t ns;
  unsigned mask;  // bit i: gpio-sim line i reads 1
};

// Reads the lines' sysfs values until stopped.
class LineSampler {
 public:
  LineSampler(const std::string& simDir, int lines) {
    for (int i = 0; i < lines; ++i) {
      const std::string path = simDir + "/sim_gpio" + std::to_string(i) + "/value";
      fds_.push_back(::open(path.c_str(), O_RDONLY));
      EXPECT_GE(fds_.back(), 0) << path;
    }
    samples_.reserve(1'000'000);
    thread_ = std::thread([this] { run(); });
  }
  ~LineSampler() {
    stop();
    for (const int fd : fds_) {
      ::close(fd);
    }
  }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) {
      thread_.join();
    }
  }
  [[nodiscard]] const std::vector<Sample>& samples() const { return samples_; }

 private:
  void run() {
    while (!stop_ && samples_.size() < samples_.capacity()) {
      unsigned mask = 0;
      for (std::size_t i = 0; i < fds_.size(); ++i) {
        char value = '0';
        if (::pread(fds_[i], &value, 1, 0) == 1 && value == '1') {
          mask |= 1U << i;
        }
      }
      samples_.push_back({monotonicNs(), mask});
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  }

  std::vector<int> fds_;
  std::vector<Sample> samples_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// A run of samples with any line high: the lines went up after `lowBeforeNs` (the last sample
// before, all low) and down before `lowAfterNs`.
struct LitRun {
  std::int64_t lowBeforeNs;
  std::int64_t lowAfterNs;
  unsigned maxMask;
  std::size_t samples;
  std::size_t allOnSamples;
};

std::vector<LitRun> litRuns(const std::vector<Sample>& samples, unsigned allOn) {
  std::vector<LitRun> runs;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    if (samples[i].mask == 0) {
      continue;
    }
    LitRun run{samples[i - 1].ns, 0, 0, 0, 0};
    for (; i < samples.size() && samples[i].mask != 0; ++i) {
      run.maxMask |= samples[i].mask;
      ++run.samples;
      run.allOnSamples += samples[i].mask == allOn ? 1U : 0U;
    }
    run.lowAfterNs = i < samples.size() ? samples[i].ns : INT64_MAX;
    runs.push_back(run);
  }
  return runs;
}

TEST(GpioSimTrigger, TheBoardsLinesAreLitAroundEveryCaptureAndOnlyThen) {
  auto board = config::loadBoard(env("SMX_BOARD"));
  ASSERT_TRUE(board) << board.error().message();
  auto boardHal = hal::createBoardHal(board->config, board->rig);
  ASSERT_TRUE(boardHal) << boardHal.error();
  hal::Hal real = (*boardHal)->hal();
  ASSERT_EQ(real.cameras.size(), 1U);
  RecordingCamera camera(*real.cameras[0]);
  hal::Camera* cameras[] = {&camera};
  const hal::Hal recorded{cameras, real.trigger, real.link, real.clock};

  device::DeviceOptions options;
  options.acquireTimeoutNs = 5'000'000'000;
  auto device = device::Device::create(*board, recorded, options);
  ASSERT_TRUE(device) << device.error();

  // The lines the board names are outputs held by the firmware; the chip's other lines are not.
  gpiod_chip* chip = gpiod_chip_open_lookup("gpiochip0");
  ASSERT_NE(chip, nullptr);
  for (unsigned offset = 0; offset < 4; ++offset) {
    gpiod_line* line = gpiod_chip_get_line(chip, offset);
    ASSERT_NE(line, nullptr);
    const bool named = offset < 2;
    EXPECT_EQ(gpiod_line_is_used(line), named) << "line " << offset;
    if (named) {
      EXPECT_EQ(gpiod_line_direction(line), GPIOD_LINE_DIRECTION_OUTPUT) << "line " << offset;
    }
  }
  gpiod_chip_close(chip);

  constexpr int kCaptures = 5;
  LineSampler sampler(env("SMX_GPIO_SIM"), 4);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  for (int i = 0; i < kCaptures; ++i) {
    auto captured = (*device)->captureOnce();
    ASSERT_TRUE(captured) << "capture " << i << ": " << captured.error().message;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  sampler.stop();

  const auto runs = litRuns(sampler.samples(), 0b11);
  ASSERT_EQ(runs.size(), static_cast<std::size_t>(kCaptures))
      << sampler.samples().size() << " samples";
  ASSERT_EQ(camera.stampsNs.size(), static_cast<std::size_t>(kCaptures));
  const std::int64_t periodNs = 1'000'000'000 / camera.format.fps;
  for (int i = 0; i < kCaptures; ++i) {
    const LitRun& run = runs[static_cast<std::size_t>(i)];
    // Both projectors together, never another line; one alone only while switching.
    EXPECT_EQ(run.maxMask, 0b11U) << "capture " << i;
    EXPECT_GE(run.allOnSamples * 10, run.samples * 9) << "capture " << i;
    // The frame's exposure began after the lines went high (its end-of-frame stamp less a
    // period), and the lines stayed high until the frame was handed over. vivid makes a frame
    // at once and stamps it 0.9 periods later, so its stamp may fall after delivery: the lines
    // are held until delivery, which on a real sensor comes after the end of the exposure.
    const auto index = static_cast<std::size_t>(i);
    const std::int64_t exposedNs = camera.stampsNs[index] - periodNs;
    EXPECT_GT(exposedNs, run.lowBeforeNs) << "capture " << i;
    EXPECT_LT(camera.deliveredNs[index], run.lowAfterNs) << "capture " << i;
    std::printf(
        "SMX-FIGURE: capture %d: lines high for %.1f ms; exposure began %.1f ms and the "
        "frame came %.1f ms after they went high\n",
        i, static_cast<double>(run.lowAfterNs - run.lowBeforeNs) / 1e6,
        static_cast<double>(exposedNs - run.lowBeforeNs) / 1e6,
        static_cast<double>(camera.deliveredNs[index] - run.lowBeforeNs) / 1e6);
  }
}

}  // namespace
}  // namespace smx
