// hal::Camera through libcamera (host builds where libcamera-dev is found). The frames come from
// libcamera's own buffers, mapped once at start(); completed requests are handed from libcamera's
// thread to acquire() through a fixed ring, so acquire() and release() do not allocate.
#include <libcamera/libcamera.h>
#include <sys/mman.h>

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <limits>
#include <mutex>
#include <system_error>
#include <vector>

#include "fresh_frame.hpp"
#include "smx/linux/libcamera_open.hpp"
#include "smx/linux/pixel_convert.hpp"

namespace smx::lnx {

namespace {

namespace lc = libcamera;
using hal::CameraState;
using hal::HalErrc;
using hal::halFail;
using hal::PixelFormat;

// DRM fourcc names count bits from the top of a little-endian word: libcamera's BGR888 is R, G,
// B in memory (V4L2's RGB24), its RGB888 is B, G, R (V4L2's BGR24).
lc::PixelFormat libcameraFormat(PixelFormat format) {
  switch (format) {
    case PixelFormat::kRgb24:
      return lc::formats::BGR888;
    case PixelFormat::kBgr24:
      return lc::formats::RGB888;
    case PixelFormat::kYuyv:
      return lc::formats::YUYV;
  }
  return lc::formats::BGR888;
}

// libcamera allows one CameraManager per process; the cameras of a board share it, and it stops
// when the last of them goes.
std::expected<std::shared_ptr<lc::CameraManager>, std::string> sharedManager() {
  static std::mutex mutex;
  static std::weak_ptr<lc::CameraManager> shared;
  const std::lock_guard lock(mutex);
  if (auto manager = shared.lock()) {
    return manager;
  }
  auto manager = std::make_shared<lc::CameraManager>();
  if (const int r = manager->start(); r < 0) {
    return std::unexpected("libcamera cannot start: " + std::system_category().message(-r));
  }
  shared = manager;
  return manager;
}

class LibcameraCamera final : public hal::Camera {
 public:
  LibcameraCamera(std::shared_ptr<lc::CameraManager> manager, std::shared_ptr<lc::Camera> camera,
                  std::string id, int buffers)
      : manager_(std::move(manager)),
        camera_(std::move(camera)),
        id_(std::move(id)),
        bufferCount_(buffers) {
    camera_->requestCompleted.connect(this, &LibcameraCamera::onRequestCompleted);
    camera_->disconnected.connect(this, &LibcameraCamera::onDisconnected);
  }

  ~LibcameraCamera() override {
    if (state_ == CameraState::kStreaming) {
      (void)stop();
    }
    camera_->requestCompleted.disconnect(this);
    camera_->disconnected.disconnect(this);
    camera_->release();
  }
  LibcameraCamera(const LibcameraCamera&) = delete;
  LibcameraCamera& operator=(const LibcameraCamera&) = delete;

  [[nodiscard]] hal::HalResult<hal::CameraFormat> configure(
      const hal::CameraFormat& wanted) override {
    if (state_ == CameraState::kStreaming) {
      return halFail(HalErrc::kInvalidState, "configure while streaming");
    }
    config_ = camera_->generateConfiguration({lc::StreamRole::VideoRecording});
    if (!config_ || config_->empty()) {
      return halFail(HalErrc::kNotSupported, "the camera offers no video stream");
    }
    lc::StreamConfiguration& stream = config_->at(0);
    const lc::Size size(static_cast<unsigned>(wanted.width), static_cast<unsigned>(wanted.height));
    stream.pixelFormat = libcameraFormat(wanted.pixelFormat);
    stream.size = size;
    stream.bufferCount = static_cast<unsigned>(bufferCount_);
    if (config_->validate() == lc::CameraConfiguration::Invalid) {
      return halFail(HalErrc::kNotSupported, "the camera cannot deliver that size and format");
    }
    if (stream.pixelFormat != libcameraFormat(wanted.pixelFormat) || stream.size != size) {
      // validate() moved the stream to the nearest it can do: say what that is. (HalError
      // holds a C string, so the message lives in the camera.)
      configureError_ = "the camera cannot deliver " + size.toString() + "-" +
                        libcameraFormat(wanted.pixelFormat).toString() +
                        "; the nearest it can is " + stream.toString();
      return halFail(HalErrc::kNotSupported, configureError_.c_str());
    }
    if (camera_->configure(config_.get()) < 0) {
      return halFail(HalErrc::kIo, "libcamera refused the configuration");
    }
    format_ = wanted;
    state_ = CameraState::kStopped;
    return format_;
  }

  [[nodiscard]] hal::HalResult<void> start() override {
    if (state_ != CameraState::kStopped) {
      return halFail(HalErrc::kInvalidState, "start while streaming or before configure");
    }
    lc::Stream* stream = config_->at(0).stream();
    allocator_ = std::make_unique<lc::FrameBufferAllocator>(camera_);
    if (allocator_->allocate(stream) < 0) {
      return halFail(HalErrc::kIo, "libcamera cannot allocate buffers");
    }
    const auto& buffers = allocator_->buffers(stream);
    const std::size_t pixels =
        static_cast<std::size_t>(format_.width) * static_cast<std::size_t>(format_.height);
    for (std::size_t i = 0; i < buffers.size(); ++i) {
      const lc::FrameBuffer::Plane& plane = buffers[i]->planes().front();
      void* mapped = ::mmap(nullptr, plane.length, PROT_READ, MAP_SHARED, plane.fd.get(),
                            static_cast<off_t>(plane.offset));
      if (mapped == MAP_FAILED) {
        unmapAll();
        return halFail(HalErrc::kIo, "cannot map a libcamera buffer", errno);
      }
      Slot slot;
      slot.mapped = static_cast<const std::byte*>(mapped);
      slot.length = plane.length;
      slot.request = camera_->createRequest(i);
      if (!slot.request || slot.request->addBuffer(stream, buffers[i].get()) < 0) {
        unmapAll();
        return halFail(HalErrc::kIo, "cannot make a libcamera request");
      }
      if (format_.pixelFormat != PixelFormat::kRgb24) {
        slot.rgb.resize(pixels);
      }
      slots_.push_back(std::move(slot));
    }
    completed_.assign(slots_.size(), nullptr);
    head_ = 0;
    count_ = 0;
    lc::ControlList controls;
    const std::int64_t periodUs = 1'000'000 / format_.fps;
    const std::array<std::int64_t, 2> limits = {periodUs, periodUs};
    controls.set(lc::controls::FrameDurationLimits, lc::Span<const std::int64_t, 2>(limits));
    if (wanted_.exposureUs) {
      controls.set(lc::controls::AeEnable, false);
      controls.set(lc::controls::ExposureTime, static_cast<std::int32_t>(*wanted_.exposureUs));
    }
    if (wanted_.gain) {
      controls.set(lc::controls::AnalogueGain, static_cast<float>(*wanted_.gain));
    }
    if (camera_->start(&controls) < 0) {
      unmapAll();
      return halFail(HalErrc::kIo, "libcamera cannot start the camera");
    }
    for (const Slot& slot : slots_) {
      (void)camera_->queueRequest(slot.request.get());
    }
    state_ = CameraState::kStreaming;
    return {};
  }

  [[nodiscard]] hal::HalResult<void> stop() override {
    if (state_ != CameraState::kStreaming) {
      return halFail(HalErrc::kInvalidState, "stop while not streaming");
    }
    camera_->stop();  // completes every queued request as cancelled
    unmapAll();
    state_ = CameraState::kStopped;
    return {};
  }

  [[nodiscard]] hal::HalResult<hal::CameraFrame> acquire(std::int64_t timeoutNs) override {
    if (lost_) {
      return halFail(HalErrc::kDisconnected, "the libcamera camera is gone", ENODEV);
    }
    if (state_ != CameraState::kStreaming) {
      return halFail(HalErrc::kInvalidState, "acquire while not streaming");
    }
    const auto called = std::chrono::steady_clock::now();
    const auto deadline = called + std::chrono::nanoseconds(timeoutNs < 0 ? 0 : timeoutNs);
    // Frames are stamped with CLOCK_MONOTONIC (steady_clock), taken as end-of-frame stamps.
    const std::int64_t freshStampNs = detail::freshFrameStampNs(
        std::chrono::duration_cast<std::chrono::nanoseconds>(called.time_since_epoch()).count(),
        format_.fps, false);
    while (true) {
      lc::Request* request = nullptr;
      {
        std::unique_lock lock(mutex_);
        if (!ready_.wait_until(lock, deadline, [this] { return count_ > 0 || lost_; })) {
          return halFail(HalErrc::kTimeout, "no frame in time");
        }
        if (lost_) {
          return halFail(HalErrc::kDisconnected, "the libcamera camera is gone", ENODEV);
        }
        request = completed_[head_];
        head_ = (head_ + 1) % completed_.size();
        --count_;
      }
      const lc::FrameBuffer* buffer = request->buffers().begin()->second;
      const lc::FrameMetadata& metadata = buffer->metadata();
      const auto index = static_cast<std::size_t>(request->cookie());
      // A bad frame, or one exposed before the call (hal::Camera::acquire): back to the camera.
      if (request->status() != lc::Request::RequestComplete ||
          metadata.status != lc::FrameMetadata::FrameSuccess ||
          static_cast<std::int64_t>(metadata.timestamp) < freshStampNs) {
        request->reuse(lc::Request::ReuseBuffers);
        (void)camera_->queueRequest(request);
        continue;
      }
      auto image = deliver(slots_[index]);
      if (!image) {
        return std::unexpected(image.error());
      }
      slots_[index].borrowed = true;
      return hal::CameraFrame{.bufferIndex = static_cast<int>(index),
                              .sequence = metadata.sequence,
                              .timestampNs = static_cast<std::int64_t>(metadata.timestamp),
                              .image = *image};
    }
  }

  [[nodiscard]] hal::HalResult<void> release(const hal::CameraFrame& frame) override {
    if (frame.bufferIndex < 0 || static_cast<std::size_t>(frame.bufferIndex) >= slots_.size() ||
        !slots_[static_cast<std::size_t>(frame.bufferIndex)].borrowed) {
      return halFail(HalErrc::kInvalidState, "release of a buffer that is not borrowed");
    }
    Slot& slot = slots_[static_cast<std::size_t>(frame.bufferIndex)];
    slot.borrowed = false;
    slot.request->reuse(lc::Request::ReuseBuffers);
    if (camera_->queueRequest(slot.request.get()) < 0) {
      return halFail(HalErrc::kIo, "libcamera refused a request");
    }
    return {};
  }

  [[nodiscard]] hal::CameraControlSupport controlSupport() const override {
    const lc::ControlInfoMap& info = camera_->controls();
    return {.exposure = info.count(lc::controls::ExposureTime.id()) > 0,
            .gain = info.count(lc::controls::AnalogueGain.id()) > 0};
  }

  // Sent with the start: libcamera takes controls per request, and the device sets them while
  // the camera is stopped.
  [[nodiscard]] hal::HalResult<void> setControls(const hal::CameraControls& controls) override {
    if (state_ == CameraState::kStreaming) {
      return halFail(HalErrc::kInvalidState, "exposure and gain are set while stopped");
    }
    const hal::CameraControlSupport support = controlSupport();
    if ((controls.exposureUs && !support.exposure) || (controls.gain && !support.gain)) {
      return halFail(HalErrc::kNotSupported, "the camera has no exposure or gain control");
    }
    const lc::ControlInfoMap& info = camera_->controls();
    const auto outside = [&](const lc::ControlId& id, double value) {
      const lc::ControlInfo& range = info.at(id.id());
      const auto bound = [](const lc::ControlValue& v) {
        switch (v.type()) {
          case lc::ControlTypeFloat:
            return static_cast<double>(v.get<float>());
          case lc::ControlTypeInteger32:
            return static_cast<double>(v.get<std::int32_t>());
          case lc::ControlTypeInteger64:
            return static_cast<double>(v.get<std::int64_t>());
          default:
            return std::numeric_limits<double>::quiet_NaN();  // no range given: unchecked
        }
      };
      return value < bound(range.min()) || value > bound(range.max());
    };
    if ((controls.exposureUs && outside(lc::controls::ExposureTime, *controls.exposureUs)) ||
        (controls.gain && outside(lc::controls::AnalogueGain, *controls.gain))) {
      return halFail(HalErrc::kInvalidArgument, "a value outside the camera's control range");
    }
    wanted_ = controls;
    return {};
  }

  [[nodiscard]] hal::CameraState state() const override { return state_; }
  [[nodiscard]] std::string_view id() const override { return id_; }

 private:
  struct Slot {
    const std::byte* mapped = nullptr;
    std::size_t length = 0;
    std::unique_ptr<lc::Request> request;
    std::vector<algo::Rgb8> rgb;  // converted frames (not RGB24)
    bool borrowed = false;
  };

  hal::HalResult<algo::ConstRgbView> deliver(Slot& slot) {
    const auto stride = static_cast<std::ptrdiff_t>(config_->at(0).stride);
    if (format_.pixelFormat == PixelFormat::kRgb24) {
      auto view = algo::ConstRgbView::create(slot.mapped, format_.width, format_.height, stride);
      if (!view) {
        return halFail(HalErrc::kIo, "the camera's frame layout is invalid");
      }
      return *view;
    }
    auto out = *algo::RgbView::packed(slot.rgb, format_.width, format_.height);
    const std::span<const std::byte> source(slot.mapped, slot.length);
    auto converted = format_.pixelFormat == PixelFormat::kYuyv
                         ? convertYuyvToRgb(source, stride, out)
                         : convertBgr24ToRgb(source, stride, out);
    if (!converted) {
      return std::unexpected(converted.error());
    }
    return algo::ConstRgbView(out);
  }

  void unmapAll() {
    for (const Slot& slot : slots_) {
      ::munmap(const_cast<std::byte*>(slot.mapped), slot.length);
    }
    slots_.clear();
    allocator_.reset();
    const std::lock_guard lock(mutex_);
    count_ = 0;
  }

  // libcamera's thread.
  void onRequestCompleted(lc::Request* request) {
    {
      const std::lock_guard lock(mutex_);
      if (request->status() == lc::Request::RequestCancelled || completed_.empty() ||
          count_ == completed_.size()) {
        return;
      }
      completed_[(head_ + count_) % completed_.size()] = request;
      ++count_;
    }
    ready_.notify_one();
  }

  void onDisconnected() {
    {
      const std::lock_guard lock(mutex_);
      lost_ = true;
    }
    ready_.notify_one();
  }

  std::shared_ptr<lc::CameraManager> manager_;  // outlives the camera
  std::shared_ptr<lc::Camera> camera_;
  std::string id_;
  int bufferCount_;
  hal::CameraFormat format_;
  CameraState state_ = CameraState::kUnconfigured;
  std::unique_ptr<lc::CameraConfiguration> config_;
  std::string configureError_;
  std::unique_ptr<lc::FrameBufferAllocator> allocator_;
  std::vector<Slot> slots_;

  std::mutex mutex_;
  std::condition_variable ready_;
  hal::CameraControls wanted_;           // sent with the next start
  std::vector<lc::Request*> completed_;  // a ring of completed requests, one slot per buffer
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  bool lost_ = false;
};

}  // namespace

bool libcameraBuilt() {
  return true;
}

std::expected<std::unique_ptr<hal::Camera>, std::string> openLibcameraCamera(
    std::string_view name, std::string_view cameraId, int buffers) {
  const std::string device = std::string(kLibcameraPrefix) + std::string(name);
  auto manager = sharedManager();
  if (!manager) {
    return std::unexpected("'" + device + "': " + manager.error());
  }
  const auto cameras = (*manager)->cameras();
  std::shared_ptr<lc::Camera> camera;
  std::string seen;
  for (const auto& candidate : cameras) {
    seen += (seen.empty() ? "" : ", ") + candidate->id();
    if (!camera && (name.empty() || candidate->id() == name)) {
      camera = candidate;
    }
  }
  if (!camera) {
    return std::unexpected("'" + device + "': no such camera (libcamera sees " +
                           (seen.empty() ? std::string("none") : seen) + ")");
  }
  if (camera->acquire() < 0) {
    return std::unexpected("'" + device + "': the camera is in use by another program");
  }
  return std::make_unique<LibcameraCamera>(std::move(*manager), std::move(camera),
                                           std::string(cameraId), buffers);
}

}  // namespace smx::lnx
