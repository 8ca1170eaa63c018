#include "range_frame.hpp"

namespace smx::host {

std::expected<ReceivedFrame, std::string> receiveRangeFrame(std::span<const std::byte> payload,
                                                            const AnnouncedFrames& /*announced*/,
                                                            std::int64_t receivedNs) {
  using Fail = std::unexpected<std::string>;
  const auto frame = protocol::decodeRangeFrame(payload);
  if (!frame) {
    return Fail(std::string("bad range frame: ") + frame.error().message);
  }
  ReceivedFrame received;
  received.header = frame->header;
  received.depth.resize(std::size_t{frame->header.width} * frame->header.height);
  if (const auto ok = protocol::decodeRangeDepth(*frame, received.depth); !ok) {
    return Fail(std::string("bad range frame: ") + ok.error().message);
  }
  received.wireBytes = protocol::kHeaderBytes + payload.size();
  received.receivedNs = receivedNs;
  return received;
}

}  // namespace smx::host
