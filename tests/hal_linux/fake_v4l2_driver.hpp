#pragma once

#include <linux/videodev2.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <utility>
#include <vector>

#include "smx/linux/v4l2_io.hpp"

// A V4L2 capture driver in memory, behind the V4l2Io seam: capabilities, format adjustment
// (sizes and pixel formats it supports), frame-rate granting, mmap buffers with the kernel's
// queue rules (QBUF of a queued buffer and REQBUFS 0 while mapped are refused, as vb2 does),
// frames produced on demand, timeouts, EINTR and the device going away. Steady-state calls
// (poll, QBUF, DQBUF, produceFrame) never allocate, so the camera's no-heap rule is testable.
namespace smx::test {

class FakeV4l2Driver final : public lnx::V4l2Io {
 public:
  struct Size {
    std::uint32_t width;
    std::uint32_t height;
  };

  // Driver behaviour, set before the camera uses it.
  std::uint32_t capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  std::vector<std::uint32_t> pixelFormats{V4L2_PIX_FMT_RGB24, V4L2_PIX_FMT_BGR24,
                                          V4L2_PIX_FMT_YUYV};
  std::vector<Size> sizes{{640, 480}, {64, 48}, {6, 3}};  // S_FMT picks the first on a miss
  std::uint32_t rowPaddingBytes = 0;                      // bytesperline = row + padding
  v4l2_fract maxRate{.numerator = 1, .denominator = 60};  // S_PARM grants at most this
  int sParmResult = 0;                                    // e.g. -ENOTTY: no frame-rate control
  std::uint32_t maxBuffers = 32;
  int pollEintrOnce = 0;  // the next poll returns -EINTR this many times
  // Controls the device has (id → range and default), and the values S_CTRL set.
  std::map<std::uint32_t, v4l2_queryctrl> controls;
  std::map<std::uint32_t, std::int32_t> controlValues;

  // The device node: present or unplugged.
  void unplug() { present_ = false; }
  void plug();
  [[nodiscard]] bool present() const { return present_; }

  // Fills the oldest queued buffer (the kernel's order) and marks it done. Without a queued
  // buffer the frame is dropped and only the sequence advances. Returns the buffer index or -1.
  template <class Fill>
  int produceFrame(Fill&& fill, std::uint32_t flags = 0) {
    const int index = takeQueued();
    if (index >= 0) {
      std::forward<Fill>(fill)(
          std::span<std::byte>(buffers_[static_cast<std::size_t>(index)].memory));
    }
    return finishFrame(index, format_.sizeimage, flags);
  }
  // A frame whose content is left as it was, with bytesused set explicitly (short frames).
  int produceRawFrame(std::uint32_t bytesUsed, std::uint32_t flags = 0) {
    return finishFrame(takeQueued(), bytesUsed, flags);
  }
  void setNextSequence(std::uint32_t sequence) { sequence_ = sequence; }
  // The time stamp of the frames produced from now on.
  void setTimestamp(std::int64_t sec, std::int64_t usec) {
    timestampSec_ = sec;
    timestampUsec_ = usec;
  }
  // What nowNs() answers: the camera's clock, against which frames are stale or fresh.
  void setNowNs(std::int64_t now) { nowNs_ = now; }

  // What the camera did to the driver.
  [[nodiscard]] const v4l2_pix_format& format() const { return format_; }
  [[nodiscard]] bool streaming() const { return streaming_; }
  [[nodiscard]] int bufferCount() const { return static_cast<int>(buffers_.size()); }
  [[nodiscard]] int mappedCount() const;
  [[nodiscard]] int queuedCount() const;  // queued and not yet filled
  [[nodiscard]] int doneCount() const { return static_cast<int>(done_.size()); }
  [[nodiscard]] int openFds() const { return openFds_; }
  [[nodiscard]] int opens() const { return opens_; }
  [[nodiscard]] int sFmtCalls() const { return sFmtCalls_; }
  [[nodiscard]] std::span<const std::byte> bufferMemory(int index) const;

  // lnx::V4l2Io
  [[nodiscard]] int open(const char* path, int flags) override;
  int close(int fd) override;
  [[nodiscard]] int ioctl(int fd, unsigned long request, void* arg) override;
  [[nodiscard]] std::expected<void*, int> mmap(int fd, std::size_t length,
                                               std::int64_t offset) override;
  int munmap(void* address, std::size_t length) override;
  [[nodiscard]] int poll(int fd, short events, std::int64_t timeoutNs, short& revents) override;
  [[nodiscard]] std::int64_t nowNs() override { return nowNs_; }

 private:
  static constexpr std::uint32_t kPage = 4096;

  struct Buffer {
    std::vector<std::byte> memory;
    bool mapped = false;
    bool queued = false;
  };

  int takeQueued();
  int finishFrame(int index, std::uint32_t bytesUsed, std::uint32_t flags);
  int setFormat(v4l2_format& format);
  int requestBuffers(v4l2_requestbuffers& request);
  int dequeue(v4l2_buffer& buffer);

  bool present_ = true;
  int generation_ = 0;  // fds of an earlier plug are dead
  int openFds_ = 0;
  int opens_ = 0;
  int sFmtCalls_ = 0;
  v4l2_pix_format format_{};
  bool streaming_ = false;
  std::vector<Buffer> buffers_;
  std::vector<Buffer> orphaned_;  // of an unplugged device, still mapped by the camera
  std::vector<int> incoming_;     // queued, in order (capacity reserved: no allocation)
  struct Done {
    int index;
    std::uint32_t bytesUsed;
    std::uint32_t flags;
    std::uint32_t sequence;
    std::int64_t timestampSec;
    std::int64_t timestampUsec;
  };
  std::vector<Done> done_;
  std::uint32_t sequence_ = 0;
  std::int64_t timestampSec_ = 100;
  std::int64_t timestampUsec_ = 0;
  std::int64_t nowNs_ = 0;
};

}  // namespace smx::test
