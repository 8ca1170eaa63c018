#include "smx/linux/v4l2_camera.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <ctime>
#include <system_error>
#include <utility>

#include "fresh_frame.hpp"
#include "smx/linux/pixel_convert.hpp"

namespace smx::lnx {

namespace {

using hal::CameraState;
using hal::HalErrc;
using hal::halFail;
using hal::PixelFormat;

constexpr std::int64_t kNsPerS = 1'000'000'000;
constexpr std::int64_t kNsPerUs = 1'000;
// Non-blocking: DQBUF must never wait, acquire() waits in poll with its own timeout.
constexpr int kOpenFlags = O_RDWR | O_NONBLOCK | O_CLOEXEC;

std::string errnoText(int err) {
  return std::generic_category().message(err);
}

// The device went away: a USB camera unplugged, a driver unbound.
bool deviceGone(int result) {
  return result == -ENODEV || result == -EIO || result == -ENXIO;
}

std::uint32_t fourcc(PixelFormat format) {
  switch (format) {
    case PixelFormat::kRgb24:
      return V4L2_PIX_FMT_RGB24;
    case PixelFormat::kBgr24:
      return V4L2_PIX_FMT_BGR24;
    case PixelFormat::kYuyv:
      return V4L2_PIX_FMT_YUYV;
  }
  return 0;
}

int bytesPerPixel(PixelFormat format) {
  return format == PixelFormat::kYuyv ? 2 : 3;
}

// Null when the device can capture single-planar video with streaming I/O.
const char* capabilityProblem(const v4l2_capability& capability) {
  const std::uint32_t caps = (capability.capabilities & V4L2_CAP_DEVICE_CAPS) != 0
                                 ? capability.device_caps
                                 : capability.capabilities;
  if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) {
    return (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) != 0
               ? "is a multi-planar capture device (not supported)"
               : "is not a video capture device";
  }
  if ((caps & V4L2_CAP_STREAMING) == 0) {
    return "does not support streaming I/O";
  }
  return nullptr;
}

std::string driverName(const v4l2_capability& capability) {
  const auto* name = reinterpret_cast<const char*>(capability.driver);
  return {name, std::find(name, name + sizeof capability.driver, '\0')};
}

v4l2_buffer mmapBuffer(int index) {
  v4l2_buffer buffer{};
  buffer.index = static_cast<std::uint32_t>(index);
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  return buffer;
}

}  // namespace

std::expected<std::unique_ptr<V4l2Camera>, std::string> V4l2Camera::create(std::string devicePath,
                                                                           std::string cameraId,
                                                                           int buffers,
                                                                           V4l2Io& io) {
  if (buffers < kMinBuffers || buffers > kMaxBuffers) {
    return std::unexpected(devicePath + ": buffers must be " + std::to_string(kMinBuffers) + ".." +
                           std::to_string(kMaxBuffers) + ", not " + std::to_string(buffers));
  }
  const int opened = io.open(devicePath.c_str(), kOpenFlags);
  if (opened < 0) {
    return std::unexpected("cannot open " + devicePath + ": " + errnoText(-opened));
  }
  V4l2Fd fd(opened, V4l2Close{&io});
  v4l2_capability capability{};
  if (const int r = io.ioctl(fd.get(), VIDIOC_QUERYCAP, &capability); r < 0) {
    return std::unexpected(devicePath + " is not a V4L2 device (VIDIOC_QUERYCAP: " + errnoText(-r) +
                           ")");
  }
  if (const char* problem = capabilityProblem(capability); problem != nullptr) {
    return std::unexpected(devicePath + " (driver " + driverName(capability) + ") " + problem);
  }
  return std::unique_ptr<V4l2Camera>(
      new V4l2Camera(std::move(devicePath), std::move(cameraId), buffers, std::move(fd), io));
}

V4l2Camera::~V4l2Camera() {
  if (!lost() && state_ == CameraState::kStreaming) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    (void)io_.ioctl(fd_.get(), VIDIOC_STREAMOFF, &type);
  }
  freeBuffers();  // REQBUFS 0 needs the descriptor, which the member closes after this body
}

hal::HalResult<hal::CameraFormat> V4l2Camera::configure(const hal::CameraFormat& wanted) {
  if (lost()) {
    return halFail(HalErrc::kDisconnected, "the camera device is gone");
  }
  if (state_ == CameraState::kStreaming) {
    return halFail(HalErrc::kInvalidState, "configure() while streaming");
  }
  if (wanted.width <= 0 || wanted.height <= 0 || wanted.fps <= 0) {
    return halFail(HalErrc::kInvalidArgument, "frame size and rate must be positive");
  }
  if (wanted.pixelFormat == PixelFormat::kYuyv && wanted.width % 2 != 0) {
    return halFail(HalErrc::kInvalidArgument, "YUYV needs an even width");
  }
  auto granted = negotiate(wanted);
  if (!granted) {
    // A lost device keeps the last good format for reopen(); otherwise the driver's format is
    // now unknown.
    if (!lost()) {
      state_ = CameraState::kUnconfigured;
    }
    return granted;
  }
  wanted_ = wanted;
  format_ = *granted;
  state_ = CameraState::kStopped;
  return granted;
}

hal::HalResult<hal::CameraFormat> V4l2Camera::negotiate(const hal::CameraFormat& wanted) {
  v4l2_format format{};
  format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  format.fmt.pix.width = static_cast<std::uint32_t>(wanted.width);
  format.fmt.pix.height = static_cast<std::uint32_t>(wanted.height);
  format.fmt.pix.pixelformat = fourcc(wanted.pixelFormat);
  format.fmt.pix.field = V4L2_FIELD_NONE;
  if (const int r = io_.ioctl(fd_.get(), VIDIOC_S_FMT, &format); r < 0) {
    if (deviceGone(r)) {
      return markLost(-r);
    }
    if (r == -EBUSY) {
      return halFail(HalErrc::kBusy, "the camera is in use (VIDIOC_S_FMT)", -r);
    }
    return halFail(HalErrc::kNotSupported, "the driver refused the format (VIDIOC_S_FMT)", -r);
  }
  // S_FMT adjusts instead of failing: a different size or format is the driver saying no.
  if (format.fmt.pix.width != static_cast<std::uint32_t>(wanted.width) ||
      format.fmt.pix.height != static_cast<std::uint32_t>(wanted.height)) {
    return halFail(HalErrc::kNotSupported, "the driver does not support this frame size");
  }
  if (format.fmt.pix.pixelformat != fourcc(wanted.pixelFormat)) {
    return halFail(HalErrc::kNotSupported, "the driver does not support this pixel format");
  }
  const auto rowBytes =
      static_cast<std::uint32_t>(bytesPerPixel(wanted.pixelFormat) * wanted.width);
  const std::uint32_t stride =
      format.fmt.pix.bytesperline == 0 ? rowBytes : format.fmt.pix.bytesperline;
  if (stride < rowBytes) {
    return halFail(HalErrc::kIo, "the driver reported a stride smaller than a row");
  }

  hal::CameraFormat granted = wanted;
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  parm.parm.capture.timeperframe = {.numerator = 1,
                                    .denominator = static_cast<std::uint32_t>(wanted.fps)};
  if (const int r = io_.ioctl(fd_.get(), VIDIOC_S_PARM, &parm); r < 0) {
    if (deviceGone(r)) {
      return markLost(-r);
    }
    // ENOTTY/EINVAL: a driver with a fixed rate it does not report; the wanted rate stands.
    if (r != -ENOTTY && r != -EINVAL) {
      return halFail(HalErrc::kIo, "VIDIOC_S_PARM failed", -r);
    }
  } else {
    const v4l2_fract perFrame = parm.parm.capture.timeperframe;
    if (perFrame.numerator > 0 && perFrame.denominator > 0) {
      // The rate granted, to the nearest frame per second (30000/1001 is 30).
      const std::uint32_t fps =
          (perFrame.denominator + perFrame.numerator / 2) / perFrame.numerator;
      granted.fps = static_cast<int>(std::max<std::uint32_t>(fps, 1));
    }
  }
  bytesPerLine_ = stride;
  frameBytes_ = sourceBytesNeeded(stride, rowBytes, wanted.height);
  return granted;
}

hal::HalResult<void> V4l2Camera::start() {
  if (lost()) {
    return halFail(HalErrc::kDisconnected, "the camera device is gone");
  }
  if (state_ != CameraState::kStopped) {
    return halFail(HalErrc::kInvalidState, state_ == CameraState::kStreaming
                                               ? "start() while streaming"
                                               : "start() before configure()");
  }
  return startStreaming();
}

hal::HalResult<void> V4l2Camera::startStreaming() {
  v4l2_requestbuffers request{};
  request.count = static_cast<std::uint32_t>(wantedBuffers_);
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  if (const int r = io_.ioctl(fd_.get(), VIDIOC_REQBUFS, &request); r < 0) {
    if (deviceGone(r)) {
      return markLost(-r);
    }
    return halFail(r == -EBUSY ? HalErrc::kBusy : HalErrc::kIo, "VIDIOC_REQBUFS failed", -r);
  }
  buffers_.resize(request.count);
  if (request.count < kMinBuffers) {
    freeBuffers();
    return halFail(HalErrc::kNotSupported, "the driver granted fewer than two buffers");
  }

  const bool converts = format_.pixelFormat != PixelFormat::kRgb24;
  for (int i = 0; i < bufferCount(); ++i) {
    v4l2_buffer query = mmapBuffer(i);
    if (const int r = io_.ioctl(fd_.get(), VIDIOC_QUERYBUF, &query); r < 0) {
      freeBuffers();
      return deviceGone(r) ? markLost(-r) : halFail(HalErrc::kIo, "VIDIOC_QUERYBUF failed", -r);
    }
    if (query.length < frameBytes_) {
      freeBuffers();
      return halFail(HalErrc::kIo, "a driver buffer is smaller than a frame");
    }
    auto mapped = io_.mmap(fd_.get(), query.length, query.m.offset);
    if (!mapped) {
      freeBuffers();
      return halFail(HalErrc::kIo, "cannot map a camera buffer", -mapped.error());
    }
    Buffer& buffer = buffers_[static_cast<std::size_t>(i)];
    buffer.mapped = static_cast<std::byte*>(*mapped);
    buffer.length = query.length;
    if (converts) {
      buffer.rgb.resize(static_cast<std::size_t>(format_.width) *
                        static_cast<std::size_t>(format_.height));
    }
  }
  for (int i = 0; i < bufferCount(); ++i) {
    if (auto queued = queue(i); !queued) {
      freeBuffers();
      return queued;
    }
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (const int r = io_.ioctl(fd_.get(), VIDIOC_STREAMON, &type); r < 0) {
    freeBuffers();
    return deviceGone(r) ? markLost(-r) : halFail(HalErrc::kIo, "VIDIOC_STREAMON failed", -r);
  }
  borrowedCount_ = 0;
  firstFrame_ = true;
  state_ = CameraState::kStreaming;
  return {};
}

hal::HalResult<void> V4l2Camera::stop() {
  if (state_ != CameraState::kStreaming && buffers_.empty()) {
    return {};  // nothing to stop; stopping twice is harmless
  }
  hal::HalResult<void> result;
  if (!lost()) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (const int r = io_.ioctl(fd_.get(), VIDIOC_STREAMOFF, &type); r < 0) {
      result = deviceGone(r) ? markLost(-r) : halFail(HalErrc::kIo, "VIDIOC_STREAMOFF failed", -r);
    }
  }
  freeBuffers();
  resumeStreaming_ = false;
  if (state_ == CameraState::kStreaming) {
    state_ = CameraState::kStopped;
  }
  return result;
}

hal::HalResult<hal::CameraFrame> V4l2Camera::acquire(std::int64_t timeoutNs) {
  if (lost()) {
    return halFail(HalErrc::kDisconnected, "the camera device is gone");
  }
  if (state_ != CameraState::kStreaming) {
    return halFail(HalErrc::kInvalidState, "acquire() while not streaming");
  }
  if (borrowedCount_ == bufferCount()) {
    return halFail(HalErrc::kBusy, "every camera buffer is borrowed");
  }
  const std::int64_t calledNs = io_.nowNs();
  const std::int64_t deadlineNs = calledNs + std::max<std::int64_t>(timeoutNs, 0);
  for (;;) {
    short revents = 0;
    const std::int64_t leftNs = std::max<std::int64_t>(deadlineNs - io_.nowNs(), 0);
    const int polled = io_.poll(fd_.get(), POLLIN, leftNs, revents);
    if (polled == -EINTR) {
      continue;
    }
    if (polled < 0) {
      return halFail(HalErrc::kIo, "poll on the camera failed", -polled);
    }
    if (polled == 0) {
      return halFail(HalErrc::kTimeout, "no frame in time");
    }
    // With a buffer queued (we checked), an error or hang-up means the device is gone.
    if ((revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
      return markLost(ENODEV);
    }
    v4l2_buffer buffer = mmapBuffer(0);
    const int r = io_.ioctl(fd_.get(), VIDIOC_DQBUF, &buffer);
    if (r == -EAGAIN) {
      continue;  // woken without a frame
    }
    if (r < 0) {
      return deviceGone(r) ? markLost(-r) : halFail(HalErrc::kIo, "VIDIOC_DQBUF failed", -r);
    }
    const auto index = static_cast<int>(buffer.index);
    if (index < 0 || index >= bufferCount()) {
      return halFail(HalErrc::kIo, "the driver returned an unknown buffer");
    }
    if ((buffer.flags & V4L2_BUF_FLAG_ERROR) != 0 || buffer.bytesused < frameBytes_ ||
        buffer.bytesused > buffers_[static_cast<std::size_t>(index)].length) {
      // A corrupt or short frame: counted, its buffer requeued, and we wait for the next one.
      ++corruptFrames_;
      if (auto queued = queue(index); !queued) {
        return std::unexpected(queued.error());
      }
      continue;
    }
    const std::int64_t timestampNs = static_cast<std::int64_t>(buffer.timestamp.tv_sec) * kNsPerS +
                                     static_cast<std::int64_t>(buffer.timestamp.tv_usec) * kNsPerUs;
    const bool monotonic =
        (buffer.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    const bool startOfExposure =
        (buffer.flags & V4L2_BUF_FLAG_TSTAMP_SRC_MASK) == V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
    if (monotonic &&
        timestampNs < detail::freshFrameStampNs(calledNs, format_.fps, startOfExposure)) {
      // Exposed before the call, so before the projectors were lit: a free-running camera
      // fills its queue while the pipeline works. Back to the driver, and wait for a new one.
      ++staleFrames_;
      if (auto queued = queue(index); !queued) {
        return std::unexpected(queued.error());
      }
      continue;
    }
    auto frame = deliver(index, buffer.bytesused, timestampNs, buffer.sequence);
    if (!frame) {
      (void)queue(index);  // not handed out: back to the driver
    }
    return frame;
  }
}

hal::HalResult<hal::CameraFrame> V4l2Camera::deliver(int index, std::uint32_t bytesUsed,
                                                     std::int64_t timestampNs,
                                                     std::uint32_t sequence) {
  Buffer& buffer = buffers_[static_cast<std::size_t>(index)];
  const auto stride = static_cast<std::ptrdiff_t>(bytesPerLine_);
  const std::span<const std::byte> source(buffer.mapped, bytesUsed);
  algo::ConstRgbView image;
  if (format_.pixelFormat == PixelFormat::kRgb24) {
    // Handed out in place: no copy for the format the pipeline takes.
    auto view = algo::ConstRgbView::create(buffer.mapped, format_.width, format_.height, stride);
    if (!view) {
      return halFail(HalErrc::kIo, "the driver's frame layout is invalid");
    }
    image = *view;
  } else {
    auto view = algo::RgbView::packed(buffer.rgb, format_.width, format_.height);
    if (!view) {
      return halFail(HalErrc::kIo, "the RGB buffer does not match the frame");
    }
    auto converted = format_.pixelFormat == PixelFormat::kYuyv
                         ? convertYuyvToRgb(source, stride, *view)
                         : convertBgr24ToRgb(source, stride, *view);
    if (!converted) {
      return std::unexpected(converted.error());
    }
    image = *view;
  }
  // Sequence numbers are 32 bits in V4L2; the difference to the last one is exact across a wrap.
  sequence_ =
      firstFrame_ ? sequence : sequence_ + static_cast<std::uint32_t>(sequence - lastSequence_);
  lastSequence_ = sequence;
  firstFrame_ = false;
  buffer.borrowed = true;
  buffer.sequence = sequence_;
  ++borrowedCount_;
  return hal::CameraFrame{
      .bufferIndex = index, .sequence = sequence_, .timestampNs = timestampNs, .image = image};
}

hal::HalResult<void> V4l2Camera::release(const hal::CameraFrame& frame) {
  const bool present = !lost();
  if (present && state_ != CameraState::kStreaming) {
    return halFail(HalErrc::kInvalidState, "release() while not streaming");
  }
  if (frame.bufferIndex < 0 || frame.bufferIndex >= bufferCount()) {
    return halFail(HalErrc::kInvalidState, "release() of a frame this camera did not hand out");
  }
  Buffer& buffer = buffers_[static_cast<std::size_t>(frame.bufferIndex)];
  if (!buffer.borrowed || buffer.sequence != frame.sequence) {
    return halFail(HalErrc::kInvalidState, "release() of a frame that is not borrowed");
  }
  buffer.borrowed = false;
  --borrowedCount_;
  if (present) {
    return queue(frame.bufferIndex);
  }
  // A lost device: no queue to put it in. The last frame given back lets go of the mappings,
  // which hold the driver (it could not be unloaded).
  if (borrowedCount_ == 0) {
    freeBuffers();
  }
  return {};
}

hal::HalResult<void> V4l2Camera::queue(int index) {
  v4l2_buffer buffer = mmapBuffer(index);
  if (const int r = io_.ioctl(fd_.get(), VIDIOC_QBUF, &buffer); r < 0) {
    return deviceGone(r) ? markLost(-r) : halFail(HalErrc::kIo, "VIDIOC_QBUF failed", -r);
  }
  return {};
}

hal::HalResult<void> V4l2Camera::reopen() {
  if (!lost()) {
    return {};
  }
  freeBuffers();  // frames from before the loss are invalid from here on
  const int opened = io_.open(path_.c_str(), kOpenFlags);
  if (opened < 0) {
    return halFail(HalErrc::kDisconnected, "the camera device is still absent", -opened);
  }
  V4l2Fd fd(opened, V4l2Close{&io_});
  v4l2_capability capability{};
  if (const int r = io_.ioctl(fd.get(), VIDIOC_QUERYCAP, &capability); r < 0) {
    return halFail(deviceGone(r) ? HalErrc::kDisconnected : HalErrc::kNotSupported,
                   "the reopened device does not answer VIDIOC_QUERYCAP", -r);
  }
  if (capabilityProblem(capability) != nullptr) {
    return halFail(HalErrc::kNotSupported, "the reopened device cannot stream video");
  }
  fd_ = std::move(fd);
  controls_ = V4l2Controls::query(io_, fd_.get());
  // The same controls the device took before: a refusal now is the device not being back.
  if (auto set = controls_.apply(io_, fd_.get(), wantedControls_); !set) {
    return markLost(set.error().sysErrno != 0 ? set.error().sysErrno : ENODEV);
  }
  if (state_ == CameraState::kUnconfigured) {
    return {};
  }
  auto granted = negotiate(wanted_);
  if (!granted) {
    if (!lost()) {
      state_ = CameraState::kUnconfigured;
      resumeStreaming_ = false;
    }
    return std::unexpected(granted.error());
  }
  format_ = *granted;
  if (!resumeStreaming_) {
    return {};
  }
  auto started = startStreaming();
  if (!lost()) {
    resumeStreaming_ = false;  // streaming again, or failed for a reason a retry will not fix
  }
  return started;
}

hal::HalResult<void> V4l2Camera::setControls(const hal::CameraControls& controls) {
  if (lost()) {
    return halFail(HalErrc::kDisconnected, "the camera device is gone");
  }
  auto set = controls_.apply(io_, fd_.get(), controls);
  if (set) {
    wantedControls_ = controls;
  }
  return set;
}

void V4l2Camera::freeBuffers() {
  if (buffers_.empty()) {
    return;
  }
  for (const Buffer& buffer : buffers_) {
    if (buffer.mapped != nullptr) {
      io_.munmap(buffer.mapped, buffer.length);
    }
  }
  buffers_.clear();
  borrowedCount_ = 0;
  if (!lost()) {
    // Unmapped first: the kernel refuses to free buffers that are still mapped.
    v4l2_requestbuffers request{};
    request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    request.memory = V4L2_MEMORY_MMAP;
    (void)io_.ioctl(fd_.get(), VIDIOC_REQBUFS, &request);
  }
}

std::unexpected<hal::HalError> V4l2Camera::markLost(int err) {
  if (fd_.valid()) {
    fd_.reset();
    ++disconnects_;
  }
  if (state_ == CameraState::kStreaming) {
    resumeStreaming_ = true;
    state_ = CameraState::kStopped;
  }
  // Mappings hold the driver's file, and so the driver; kept only for frames still borrowed.
  if (borrowedCount_ == 0) {
    freeBuffers();
  }
  return halFail(HalErrc::kDisconnected, "the camera device is gone", err);
}

}  // namespace smx::lnx
