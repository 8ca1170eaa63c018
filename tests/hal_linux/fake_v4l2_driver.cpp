#include "fake_v4l2_driver.hpp"

#include <poll.h>

#include <algorithm>
#include <cerrno>

namespace smx::test {

namespace {

std::uint32_t bytesPerPixel(std::uint32_t fourcc) {
  return fourcc == V4L2_PIX_FMT_YUYV ? 2 : 3;
}

}  // namespace

void FakeV4l2Driver::plug() {
  // A new device instance: fresh driver state, the old buffers live on while mapped.
  for (Buffer& buffer : buffers_) {
    orphaned_.push_back(std::move(buffer));
  }
  buffers_.clear();
  incoming_.clear();
  done_.clear();
  streaming_ = false;
  format_ = {};
  present_ = true;
  ++generation_;
}

int FakeV4l2Driver::mappedCount() const {
  return static_cast<int>(
      std::count_if(buffers_.begin(), buffers_.end(), [](const Buffer& b) { return b.mapped; }) +
      std::count_if(orphaned_.begin(), orphaned_.end(), [](const Buffer& b) { return b.mapped; }));
}

int FakeV4l2Driver::queuedCount() const {
  return static_cast<int>(incoming_.size());
}

std::span<const std::byte> FakeV4l2Driver::bufferMemory(int index) const {
  return buffers_[static_cast<std::size_t>(index)].memory;
}

int FakeV4l2Driver::takeQueued() {
  if (!streaming_ || incoming_.empty()) {
    return -1;
  }
  const int index = incoming_.front();
  incoming_.erase(incoming_.begin());
  return index;
}

int FakeV4l2Driver::finishFrame(int index, std::uint32_t bytesUsed, std::uint32_t flags) {
  const std::uint32_t sequence = sequence_++;
  if (index < 0) {
    return -1;  // no buffer to fill: a dropped frame
  }
  // Stamped when done, as a driver does.
  done_.push_back(Done{.index = index,
                       .bytesUsed = bytesUsed,
                       .flags = flags,
                       .sequence = sequence,
                       .timestampSec = timestampSec_,
                       .timestampUsec = timestampUsec_});
  return index;
}

int FakeV4l2Driver::open(const char* /*path*/, int /*flags*/) {
  if (!present_) {
    return -ENOENT;
  }
  ++openFds_;
  ++opens_;
  return 10 + generation_;
}

int FakeV4l2Driver::close(int fd) {
  if (fd < 10) {
    return -EBADF;
  }
  --openFds_;
  return 0;
}

int FakeV4l2Driver::ioctl(int fd, unsigned long request, void* arg) {
  if (!present_ || fd != 10 + generation_) {
    return -ENODEV;
  }
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto& cap = *static_cast<v4l2_capability*>(arg);
      cap = {};
      std::copy_n("fake", 5, reinterpret_cast<char*>(cap.driver));
      cap.capabilities = capabilities | V4L2_CAP_DEVICE_CAPS;
      cap.device_caps = capabilities;
      return 0;
    }
    case VIDIOC_S_FMT:
      return setFormat(*static_cast<v4l2_format*>(arg));
    case VIDIOC_S_PARM: {
      if (sParmResult != 0) {
        return sParmResult;
      }
      auto& parm = *static_cast<v4l2_streamparm*>(arg);
      v4l2_fract& perFrame = parm.parm.capture.timeperframe;
      // Longer frame time wins: a/b < c/d  <=>  a*d < c*b.
      if (std::uint64_t{perFrame.numerator} * maxRate.denominator <
          std::uint64_t{maxRate.numerator} * perFrame.denominator) {
        perFrame = maxRate;
      }
      parm.parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
      return 0;
    }
    case VIDIOC_REQBUFS:
      return requestBuffers(*static_cast<v4l2_requestbuffers*>(arg));
    case VIDIOC_QUERYBUF: {
      auto& buffer = *static_cast<v4l2_buffer*>(arg);
      if (buffer.index >= buffers_.size()) {
        return -EINVAL;
      }
      buffer.length = static_cast<std::uint32_t>(buffers_[buffer.index].memory.size());
      buffer.m.offset = buffer.index * kPage;
      return 0;
    }
    case VIDIOC_QBUF: {
      const auto& buffer = *static_cast<v4l2_buffer*>(arg);
      if (buffer.index >= buffers_.size() || buffers_[buffer.index].queued) {
        return -EINVAL;
      }
      buffers_[buffer.index].queued = true;
      incoming_.push_back(static_cast<int>(buffer.index));
      return 0;
    }
    case VIDIOC_DQBUF:
      return dequeue(*static_cast<v4l2_buffer*>(arg));
    case VIDIOC_STREAMON:
      if (buffers_.empty()) {
        return -EINVAL;
      }
      streaming_ = true;
      return 0;
    case VIDIOC_QUERYCTRL: {
      auto& query = *static_cast<v4l2_queryctrl*>(arg);
      const auto it = controls.find(query.id);
      if (it == controls.end()) {
        return -EINVAL;
      }
      query = it->second;
      return 0;
    }
    case VIDIOC_S_CTRL: {
      const auto& control = *static_cast<v4l2_control*>(arg);
      const auto it = controls.find(control.id);
      if (it == controls.end()) {
        return -EINVAL;
      }
      if (control.value < it->second.minimum || control.value > it->second.maximum) {
        return -ERANGE;
      }
      controlValues[control.id] = control.value;
      return 0;
    }
    case VIDIOC_STREAMOFF:
      // The kernel hands every buffer back to user space, queued or done.
      streaming_ = false;
      for (Buffer& buffer : buffers_) {
        buffer.queued = false;
      }
      incoming_.clear();
      done_.clear();
      return 0;
    default:
      return -ENOTTY;
  }
}

int FakeV4l2Driver::setFormat(v4l2_format& format) {
  ++sFmtCalls_;
  if (streaming_ || !buffers_.empty()) {
    return -EBUSY;
  }
  v4l2_pix_format& pix = format.fmt.pix;
  if (std::find(pixelFormats.begin(), pixelFormats.end(), pix.pixelformat) == pixelFormats.end()) {
    pix.pixelformat = pixelFormats.front();
  }
  const bool sizeSupported = std::any_of(sizes.begin(), sizes.end(), [&](const Size& s) {
    return s.width == pix.width && s.height == pix.height;
  });
  if (!sizeSupported) {
    pix.width = sizes.front().width;
    pix.height = sizes.front().height;
  }
  pix.field = V4L2_FIELD_NONE;
  pix.bytesperline = pix.width * bytesPerPixel(pix.pixelformat) + rowPaddingBytes;
  pix.sizeimage = pix.bytesperline * pix.height;
  format_ = pix;
  return 0;
}

int FakeV4l2Driver::requestBuffers(v4l2_requestbuffers& request) {
  if (request.memory != V4L2_MEMORY_MMAP || streaming_) {
    return -EINVAL;
  }
  if (std::any_of(buffers_.begin(), buffers_.end(), [](const Buffer& b) { return b.mapped; })) {
    return -EBUSY;  // vb2 refuses to free buffers that are still mapped
  }
  buffers_.clear();
  incoming_.clear();
  done_.clear();
  request.count = std::min(request.count, maxBuffers);
  buffers_.resize(request.count);
  for (Buffer& buffer : buffers_) {
    buffer.memory.assign(format_.sizeimage, std::byte{0});
  }
  incoming_.reserve(request.count);
  done_.reserve(request.count);
  return 0;
}

int FakeV4l2Driver::dequeue(v4l2_buffer& buffer) {
  if (!streaming_) {
    return -EINVAL;
  }
  if (done_.empty()) {
    return -EAGAIN;
  }
  const Done done = done_.front();
  done_.erase(done_.begin());
  buffers_[static_cast<std::size_t>(done.index)].queued = false;
  buffer.index = static_cast<std::uint32_t>(done.index);
  buffer.bytesused = done.bytesUsed;
  buffer.flags = done.flags | V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
  buffer.sequence = done.sequence;
  buffer.timestamp.tv_sec = done.timestampSec;
  buffer.timestamp.tv_usec = done.timestampUsec;
  buffer.length =
      static_cast<std::uint32_t>(buffers_[static_cast<std::size_t>(done.index)].memory.size());
  return 0;
}

std::expected<void*, int> FakeV4l2Driver::mmap(int fd, std::size_t length, std::int64_t offset) {
  if (!present_ || fd != 10 + generation_) {
    return std::unexpected(-ENODEV);
  }
  const auto index = static_cast<std::size_t>(offset / kPage);
  if (offset % kPage != 0 || index >= buffers_.size() || length != buffers_[index].memory.size()) {
    return std::unexpected(-EINVAL);
  }
  buffers_[index].mapped = true;
  return buffers_[index].memory.data();
}

int FakeV4l2Driver::munmap(void* address, std::size_t /*length*/) {
  for (std::vector<Buffer>* list : {&buffers_, &orphaned_}) {
    for (Buffer& buffer : *list) {
      if (buffer.memory.data() == address && buffer.mapped) {
        buffer.mapped = false;
        return 0;
      }
    }
  }
  return -EINVAL;
}

int FakeV4l2Driver::poll(int fd, short /*events*/, std::int64_t /*timeoutNs*/, short& revents) {
  if (pollEintrOnce > 0) {
    --pollEintrOnce;
    return -EINTR;
  }
  if (!present_ || fd != 10 + generation_) {
    revents = POLLERR | POLLHUP;
    return 1;
  }
  if (done_.empty()) {
    return 0;  // nothing arrives in a test's time: a timeout
  }
  revents = POLLIN;
  return 1;
}

}  // namespace smx::test
