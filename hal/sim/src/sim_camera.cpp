#include "sim_camera.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

namespace smx::sim {

namespace {
using hal::CameraState;
using hal::HalErrc;
using hal::halFail;
constexpr std::int64_t kNsPerS = 1'000'000'000;
}  // namespace

SimCamera::SimCamera(std::string id, SimCameraSource source, const SimTrigger& trigger,
                     hal::Clock& clock, hal::CameraFormat nativeFormat, int buffers)
    : id_(std::move(id)),
      source_(source),
      trigger_(trigger),
      clock_(clock),
      native_(nativeFormat),
      format_(nativeFormat),
      bufferCount_(buffers) {}

hal::HalResult<hal::CameraFormat> SimCamera::configure(const hal::CameraFormat& wanted) {
  if (state_ == CameraState::kStreaming) {
    return halFail(HalErrc::kInvalidState, "configure while streaming");
  }
  if (wanted.width != native_.width || wanted.height != native_.height) {
    return halFail(HalErrc::kNotSupported, "the simulated camera has the rig's image size only");
  }
  if (wanted.fps < 1 || wanted.fps > 1000) {
    return halFail(HalErrc::kInvalidArgument, "frame rate outside 1..1000 fps");
  }
  // Any wire format: the simulated sensor delivers RGB, as a backend does after converting.
  format_ = wanted;
  state_ = CameraState::kStopped;
  return format_;
}

hal::HalResult<void> SimCamera::start() {
  if (state_ != CameraState::kStopped) {
    return halFail(HalErrc::kInvalidState, state_ == CameraState::kStreaming
                                               ? "start while streaming"
                                               : "start before configure");
  }
  const auto pixels =
      static_cast<std::size_t>(format_.width) * static_cast<std::size_t>(format_.height);
  buffers_.assign(static_cast<std::size_t>(bufferCount_), std::vector<algo::Rgb8>(pixels));
  borrowed_.assign(static_cast<std::size_t>(bufferCount_), false);
  streamStartNs_ = clock_.nowNs();
  sequence_ = 0;
  state_ = CameraState::kStreaming;
  return {};
}

hal::HalResult<void> SimCamera::stop() {
  if (state_ != CameraState::kStreaming) {
    return halFail(HalErrc::kInvalidState, "stop while not streaming");
  }
  borrowed_.assign(borrowed_.size(), false);
  state_ = CameraState::kStopped;
  return {};
}

hal::HalResult<hal::CameraFrame> SimCamera::acquire(std::int64_t timeoutNs) {
  if (state_ != CameraState::kStreaming) {
    return halFail(HalErrc::kInvalidState, "acquire while not streaming");
  }
  if (!connected_) {
    return halFail(HalErrc::kDisconnected, "the simulated camera is disconnected", ENODEV);
  }
  if (pendingTimeouts_ > 0) {
    --pendingTimeouts_;
    return halFail(HalErrc::kTimeout, "no frame from the simulated camera in time");
  }
  const auto free = std::ranges::find(borrowed_, false);
  if (free == borrowed_.end()) {
    return halFail(HalErrc::kBusy, "every buffer is borrowed; release one first");
  }
  // Frame k is exposed from start + k / fps; frames whose exposure began before the ask are lost
  // (their light came before the projectors' trigger), so the first one handed out is the next.
  const std::int64_t periodNs = kNsPerS / format_.fps;
  const std::int64_t now = clock_.nowNs();
  const auto due = [&](std::uint64_t k) {
    return streamStartNs_ + static_cast<std::int64_t>(k) * periodNs;
  };
  const auto first = static_cast<std::uint64_t>((now - streamStartNs_ + periodNs - 1) / periodNs);
  std::uint64_t next = std::max(sequence_ + 1, first);
  next += static_cast<std::uint64_t>(pendingDrops_.exchange(0));
  if (due(next) - now > timeoutNs) {
    clock_.sleepUntilNs(now + timeoutNs);
    return halFail(HalErrc::kTimeout, "no frame from the simulated camera in time");
  }
  clock_.sleepUntilNs(due(next));
  sequence_ = next;

  const int index = static_cast<int>(free - borrowed_.begin());
  if (auto made = produce(index); !made) {
    return std::unexpected(made.error());
  }
  borrowed_[static_cast<std::size_t>(index)] = true;
  ++delivered_;
  auto& pixels = buffers_[static_cast<std::size_t>(index)];
  // Stamped when the simulated exposure is over: rendering stands for the physical world (and
  // is slow), not for the camera's delivery.
  return hal::CameraFrame{
      .bufferIndex = index,
      .sequence = sequence_,
      .timestampNs = clock_.nowNs(),
      .image = *algo::ConstRgbView::packed(pixels, format_.width, format_.height)};
}

hal::HalResult<void> SimCamera::produce(int buffer) {
  auto& pixels = buffers_[static_cast<std::size_t>(buffer)];
  const std::uint32_t lit = trigger_.active();
  lastExposureMask_ = lit;
  if (source_.replay != nullptr) {
    const auto& image = (*source_.replay)[delivered_ % source_.replay->size()];
    std::memcpy(pixels.data(), image.pixels.data(), pixels.size() * sizeof(algo::Rgb8));
    return {};
  }
  FrameRequest request;
  request.camera = source_.rigCamera;
  request.frame = static_cast<int>(delivered_);
  request.seed = source_.seed;
  for (int p = 0; p < trigger_.count(); ++p) {
    request.lit.push_back(((lit >> p) & 1U) != 0);
  }
  request.power.assign(request.lit.size(), trigger_.power() / 100.0);
  request.exposureScale = static_cast<double>(exposureUs_) / kSimNominalExposureUs;
  request.gain = gain_;
  request.turntableDeg = source_.turntable != nullptr ? source_.turntable->angleDeg() : 0.0;
  auto view = *algo::RgbView::packed(pixels, format_.width, format_.height);
  if (!source_.renderer->render(request, view, nullptr)) {
    return halFail(HalErrc::kIo, "the simulator could not render the frame");
  }
  return {};
}

hal::CameraControlSupport SimCamera::controlSupport() const {
  // Replayed images were taken as they are: nothing changes their light.
  const bool rendered = source_.replay == nullptr;
  return {.exposure = rendered, .gain = rendered};
}

hal::HalResult<void> SimCamera::setControls(const hal::CameraControls& controls) {
  const hal::CameraControlSupport support = controlSupport();
  if ((controls.exposureUs && !support.exposure) || (controls.gain && !support.gain)) {
    return hal::halFail(hal::HalErrc::kNotSupported,
                        "a replaying simulated camera has no exposure or gain control");
  }
  if (controls.exposureUs &&
      (*controls.exposureUs < 1 || *controls.exposureUs > kSimMaxExposureUs)) {
    return hal::halFail(hal::HalErrc::kInvalidArgument,
                        "the simulated camera's exposure is 1 us to 1 s");
  }
  if (controls.gain &&
      (!std::isfinite(*controls.gain) || *controls.gain < 1.0 || *controls.gain > kSimMaxGain)) {
    return hal::halFail(hal::HalErrc::kInvalidArgument, "the simulated camera's gain is 1 to 16");
  }
  exposureUs_ = controls.exposureUs.value_or(kSimNominalExposureUs);
  gain_ = controls.gain.value_or(1.0);
  return {};
}

hal::HalResult<void> SimCamera::recover() {
  if (!connected_) {
    return halFail(HalErrc::kDisconnected, "the simulated camera is still disconnected", ENODEV);
  }
  // Like a reopened device: the buffers handed out before are gone.
  borrowed_.assign(borrowed_.size(), false);
  return {};
}

hal::HalResult<void> SimCamera::release(const hal::CameraFrame& frame) {
  if (state_ != CameraState::kStreaming) {
    return halFail(HalErrc::kInvalidState, "release while not streaming");
  }
  if (frame.bufferIndex < 0 || frame.bufferIndex >= bufferCount_ ||
      !borrowed_[static_cast<std::size_t>(frame.bufferIndex)]) {
    return halFail(HalErrc::kInvalidState, "release of a buffer that is not borrowed");
  }
  borrowed_[static_cast<std::size_t>(frame.bufferIndex)] = false;
  return {};
}

}  // namespace smx::sim
