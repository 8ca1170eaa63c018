// The capture loop: per frame integer-only (the pipeline) and allocation-free.
#include <algorithm>
#include <array>
#include <cstdio>
#include <thread>

#include "smx/device/device.hpp"

namespace smx::device {

namespace {
constexpr std::int64_t kRecoveryWaitNs = 100'000'000;  // between attempts to reopen a camera
}  // namespace

hal::HalResult<void> Device::captureOnce() {
  if (auto on = hal_.trigger.set(rangeProjectorsMask_); !on) {
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

bool Device::serveRawCapture() {
  auto requested = RawState::kRequested;
  if (!rawState_.compare_exchange_strong(requested, RawState::kCapturing)) {
    return false;
  }
  rawSize_ = captureRaw(rawMask_);
  ++counters_.rawCaptures;
  rawState_ = RawState::kReady;  // publishes raw_ to the network loop
  return true;
}

std::size_t Device::rawError(std::string_view what, const hal::HalError& error) {
  ++counters_.captureErrors;
  std::array<char, 256> text{};
  const int length = std::snprintf(text.data(), text.size(), "capture-raw: %.*s: %s (%s)",
                                   static_cast<int>(what.size()), what.data(), error.message,
                                   hal::toString(error.code));
  const protocol::ErrorMessage message{
      protocol::ErrorCode::kInternal,
      std::string_view(text.data(), static_cast<std::size_t>(std::clamp(length, 0, 255)))};
  const auto encoded = protocol::encode(message, raw_);
  return encoded ? encoded->size() : 0;
}

std::size_t Device::captureRaw(std::uint32_t mask) {
  if (auto on = hal_.trigger.set(mask); !on) {
    return rawError("trigger lines", on.error());
  }
  if (leadNs_ > 0) {
    hal_.clock.sleepUntilNs(hal_.clock.nowNs() + leadNs_);
  }
  std::size_t acquired = 0;
  std::size_t size = 0;
  bool failed = false;
  for (hal::Camera* camera : hal_.cameras) {
    auto frame = camera->acquire(options_.acquireTimeoutNs);
    if (!frame) {
      size = rawError(camera->id(), frame.error());
      failed = true;
      break;
    }
    frames_[acquired++] = *frame;
  }
  (void)hal_.trigger.set(0);
  counters_.framesCaptured += acquired;
  const std::uint64_t number = counters_.rawCaptures;
  for (std::size_t i = 0; !failed && i < acquired; ++i) {
    const algo::ConstRgbView image = frames_[i].image;
    const int band = protocol::rawFrameBandRows(image.width());
    for (int row = 0; !failed && row < image.height(); row += band) {
      const protocol::RawFrameHeader header{
          .camera = static_cast<std::uint8_t>(i),
          .projectorsMask = mask,
          .firstRow = static_cast<std::uint16_t>(row),
          .rows = static_cast<std::uint16_t>(std::min(band, image.height() - row)),
          .capture = number,
          .captureTimestampNs = frames_[i].timestampNs};
      const auto message = protocol::encodeRawFrame(header, image, std::span(raw_).subspan(size));
      if (!message) {
        // raw_ holds every camera's bands at the board's size; a frame of another size is not
        // the camera the board describes.
        size = rawError(hal_.cameras[i]->id(),
                        hal::HalError{hal::HalErrc::kInvalidArgument,
                                      "frame does not match the board's camera size"});
        failed = true;
        continue;
      }
      size += message->size();
    }
  }
  for (std::size_t i = 0; i < acquired; ++i) {
    (void)hal_.cameras[i]->release(frames_[i]);
  }
  return size;
}

void Device::runCapture(const std::atomic<bool>& stop) {
  while (!stop) {
    (void)serveRawCapture();
    (void)serveTurn();
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
