// libFuzzer target for range frames on the host (smx::host::receiveRangeFrame): the first five
// bytes are what the device announced (cameras 1-4, width and height 1-512; bit 7 of the first:
// a frame with its confidence plane, message 9), the rest is the payload. Any bytes are a frame of
// the announced camera count and size or an error, never a crash, a sanitizer report or an
// allocation sized by the frame's own header.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "range_frame.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr std::size_t kAnnouncement = 5;
  if (size < kAnnouncement) {
    return 0;
  }
  const smx::host::AnnouncedFrames announced = {.cameras = data[0] % 4 + 1,
                                                .width = (data[1] | data[2] << 8U) % 512 + 1,
                                                .height = (data[3] | data[4] << 8U) % 512 + 1};
  const auto payload = std::as_bytes(std::span(data + kAnnouncement, size - kAnnouncement));
  const bool withConfidence = (data[0] & 0x80U) != 0;
  const auto type = withConfidence ? smx::protocol::MessageType::kRangeFrameConfidence
                                   : smx::protocol::MessageType::kRangeFrame;
  const auto frame = smx::host::receiveRangeFrame(payload, announced, 0, type);
  const std::size_t pixels =
      static_cast<std::size_t>(announced.width) * static_cast<std::size_t>(announced.height);
  if (frame &&
      (frame->header.camera >= announced.cameras || frame->header.width != announced.width ||
       frame->header.height != announced.height || frame->depth.size() != pixels ||
       frame->confidence.size() != (withConfidence ? pixels : 0))) {
    std::abort();
  }
  return 0;
}
