// libFuzzer target for range and raw frames on the host (smx::host::receiveRangeFrame,
// RawFrameAssembler): the first five bytes are what the device announced (cameras 1-4, width and
// height 1-512; bit 7 of the first: a frame with its confidence plane, message 9; bit 6: raw-frame
// bands instead, records of [length u16, payload], asked with projector mask bit 5 of the first
// byte), the rest is the payload. Any bytes are a frame of the announced camera count and size or
// an error, never a crash, a sanitizer report or an allocation sized by the frame's own header.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "range_frame.hpp"
#include "raw_frames.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr std::size_t kAnnouncement = 5;
  if (size < kAnnouncement) {
    return 0;
  }
  const smx::host::AnnouncedFrames announced = {.cameras = data[0] % 4 + 1,
                                                .width = (data[1] | data[2] << 8U) % 512 + 1,
                                                .height = (data[3] | data[4] << 8U) % 512 + 1};
  auto payload = std::as_bytes(std::span(data + kAnnouncement, size - kAnnouncement));
  const std::size_t pixels =
      static_cast<std::size_t>(announced.width) * static_cast<std::size_t>(announced.height);
  if ((data[0] & 0x40U) != 0) {
    auto assembler = smx::host::RawFrameAssembler::create(announced, (data[0] >> 5U) & 1U);
    if (!assembler) {
      std::abort();  // the announcement is within the limits
    }
    // Bands until one is refused or the input ends; a refused band ends the capture.
    while (payload.size() >= 2 && !assembler->complete()) {
      const std::size_t length = std::min<std::size_t>(
          payload.size() - 2, std::to_integer<std::size_t>(payload[0]) |
                                  std::to_integer<std::size_t>(payload[1]) << 8U);
      if (!assembler->add(payload.subspan(2, length))) {
        return 0;
      }
      payload = payload.subspan(2 + length);
    }
    if (assembler->complete()) {
      const auto capture = assembler->take();
      if (capture.images.size() != static_cast<std::size_t>(announced.cameras)) {
        std::abort();
      }
      for (const auto& image : capture.images) {
        if (image.size() != pixels) {
          std::abort();
        }
      }
    }
    return 0;
  }
  const bool withConfidence = (data[0] & 0x80U) != 0;
  const auto type = withConfidence ? smx::protocol::MessageType::kRangeFrameConfidence
                                   : smx::protocol::MessageType::kRangeFrame;
  const auto frame = smx::host::receiveRangeFrame(payload, announced, 0, type);
  if (frame &&
      (frame->header.camera >= announced.cameras || frame->header.width != announced.width ||
       frame->header.height != announced.height || frame->depth.size() != pixels ||
       frame->confidence.size() != (withConfidence ? pixels : 0))) {
    std::abort();
  }
  return 0;
}
