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

Device::Acquired Device::acquireFrames(std::uint32_t mask, std::vector<hal::CameraFrame>& frames) {
  Acquired got;
  if (auto on = hal_.trigger.set(mask); !on) {
    got.status = on;
    got.failed = "trigger lines";
    return got;
  }
  got.triggered = true;
  if (leadNs_ > 0) {
    hal_.clock.sleepUntilNs(hal_.clock.nowNs() + leadNs_);
  }
  for (hal::Camera* camera : hal_.cameras) {
    auto frame = camera->acquire(options_.acquireTimeoutNs);
    if (!frame) {
      got.status = std::unexpected(frame.error());
      got.failed = camera->id();
      break;
    }
    frames[got.count++] = *frame;
  }
  (void)hal_.trigger.set(0);  // a line that cannot be cleared fails the next set() too
  counters_.framesCaptured += got.count;
  return got;
}

void Device::releaseFrames(const std::vector<hal::CameraFrame>& frames, std::size_t count) const {
  for (std::size_t i = 0; i < count; ++i) {
    (void)hal_.cameras[i]->release(frames[i]);
  }
}

// A failed capture returns with nothing decoding, so that recover() may take back every buffer.
hal::HalResult<void> Device::captureOnce() {
  // The capture goes to next_, as frames_ may still be decoding. Pipelined, just in time: the
  // frame that arrives as the decoding ends, not one that would wait a whole decode for it.
  if (decoding_ && decodingCount_ > 0) {
    const std::int64_t ready = decodeStartNs_ + lastDecodeNs_ - framePeriodNs_;
    if (ready > hal_.clock.nowNs()) {
      hal_.clock.sleepUntilNs(ready);
    }
  }
  const Acquired got = acquireFrames(rangeProjectorsMask_, next_);
  finishCapture();
  if (!got.status) {
    ++counters_.captureErrors;
    releaseFrames(next_, got.count);
    captureNumber_ += got.triggered ? 1 : 0;
    return got.status;
  }
  std::swap(frames_, next_);  // the new capture is the one to decode
  decodingCount_ = got.count;
  decodingNumber_ = captureNumber_++;
  decodeStartNs_ = hal_.clock.nowNs();
  if (decoding_) {
    decoding_->start(this, [](void* device) { static_cast<Device*>(device)->decodeFrames(); });
  } else {
    decodeFrames();
    finishCapture();
  }
  return got.status;
}

void Device::finishCapture() {
  if (decoding_) {
    decoding_->wait();
  }
  releaseFrames(frames_, decodingCount_);
  decodingCount_ = 0;
}

void Device::decodeFrames() {
  auto job = [this](int camera) { decodeCamera(camera); };
  workers_->forEach(static_cast<int>(decodingCount_), job);
  lastDecodeNs_ = hal_.clock.nowNs() - decodeStartNs_;
}

void Device::decodeCamera(int camera) {
  const auto i = static_cast<std::size_t>(camera);
  const std::int64_t start = hal_.clock.nowNs();
  if (!cameras_[i].pipeline->run(frames_[i].image, *cameras_[i].jobs)) {
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
                                          .frame = decodingNumber_,
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
  finishCapture();  // captureRaw() borrows into frames_
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
  const Acquired got = acquireFrames(mask, frames_);
  const std::size_t acquired = got.count;
  bool failed = !got.status;
  std::size_t size = failed ? rawError(got.failed, got.status.error()) : 0;
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
  finishCapture();
}

}  // namespace smx::device
