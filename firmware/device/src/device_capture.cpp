// The capture loop: per frame integer-only (the pipeline) and allocation-free.
#include <thread>

#include "smx/device/device.hpp"

namespace smx::device {

namespace {
constexpr std::int64_t kRecoveryWaitNs = 100'000'000;  // between attempts to reopen a camera
}  // namespace

hal::HalResult<void> Device::captureOnce() {
  if (auto on = hal_.trigger.set(allProjectorsMask_); !on) {
    ++counters_.captureErrors;
    return on;
  }
  if (leadNs_ > 0) {
    hal_.clock.sleepUntilNs(hal_.clock.nowNs() + leadNs_);
  }
  std::size_t acquired = 0;
  hal::HalResult<void> status;
  for (hal::Camera* camera : hal_.cameras) {
    auto frame = camera->acquire(options_.acquireTimeoutNs);
    if (!frame) {
      status = std::unexpected(frame.error());
      break;
    }
    frames_[acquired++] = *frame;
  }
  (void)hal_.trigger.set(0);  // a line that cannot be cleared fails the next set() too
  counters_.framesCaptured += acquired;

  if (status) {
    auto job = [this](int camera) { decodeCamera(camera); };
    workers_->run(static_cast<int>(acquired), job);
  } else {
    ++counters_.captureErrors;
  }
  for (std::size_t i = 0; i < acquired; ++i) {
    (void)hal_.cameras[i]->release(frames_[i]);
  }
  ++captureNumber_;
  return status;
}

void Device::decodeCamera(int camera) {
  const auto i = static_cast<std::size_t>(camera);
  const std::int64_t start = hal_.clock.nowNs();
  if (!cameras_[i].pipeline->run(frames_[i].image)) {
    ++counters_.captureErrors;
    return;
  }
  const auto decodeUs = static_cast<std::uint32_t>((hal_.clock.nowNs() - start) / 1000);
  counters_.decodeTimeUsLast = decodeUs;
  counters_.decodeTimeUsTotal += decodeUs;
  ++counters_.framesDecoded;
  if (streaming_) {
    queueRangeFrame(camera, frames_[i], decodeUs);
  }
}

void Device::queueRangeFrame(int camera, const hal::CameraFrame& frame, std::uint32_t decodeUs) {
  const protocol::RangeFrameHeader header{.camera = static_cast<std::uint8_t>(camera),
                                          .compression = compression_,
                                          .frame = captureNumber_,
                                          .captureTimestampNs = frame.timestampNs,
                                          .sentTimestampNs = hal_.clock.nowNs(),
                                          .depthUnitNm = depthUnitNm_,
                                          .decodeTimeUs = decodeUs};
  const SendQueue::WriteSlot slot = queue_.beginWrite();
  const algo::CameraPipeline& pipeline = *cameras_[static_cast<std::size_t>(camera)].pipeline;
  const auto message =
      confidence_
          ? protocol::encodeRangeFrame(header, pipeline.merged(), pipeline.confidence(), slot.bytes)
          : protocol::encodeRangeFrame(header, pipeline.merged(), slot.bytes);
  if (!message) {
    queue_.abandon(slot);
    ++counters_.captureErrors;
    return;
  }
  queue_.commit(slot, message->size());
  ++counters_.framesQueued;
}

void Device::runCapture(const std::atomic<bool>& stop) {
  while (!stop) {
    const auto captured = captureOnce();
    if (!captured && captured.error().code == hal::HalErrc::kDisconnected) {
      // Try to bring every camera back, then capture again; the host keeps its connection.
      for (hal::Camera* camera : hal_.cameras) {
        (void)camera->recover();
      }
      hal_.clock.sleepUntilNs(hal_.clock.nowNs() + kRecoveryWaitNs);
    }
  }
}

}  // namespace smx::device
