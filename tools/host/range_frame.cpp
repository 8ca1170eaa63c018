#include "range_frame.hpp"

namespace smx::host {

std::expected<ReceivedFrame, std::string> receiveRangeFrame(std::span<const std::byte> payload,
                                                            const AnnouncedFrames& announced,
                                                            std::int64_t receivedNs,
                                                            protocol::MessageType type) {
  using Fail = std::unexpected<std::string>;
  const auto frame = protocol::decodeRangeFrame(payload, type);
  if (!frame) {
    return Fail(std::string("bad range frame: ") + frame.error().message);
  }
  const protocol::RangeFrameHeader& header = frame->header;
  if (header.camera >= announced.cameras) {
    return Fail("bad range frame: camera " + std::to_string(header.camera) +
                ", but the device announced " + std::to_string(announced.cameras) + " camera(s)");
  }
  if (header.width != announced.width || header.height != announced.height) {
    return Fail("bad range frame: " + std::to_string(header.width) + "x" +
                std::to_string(header.height) + ", but the device announced " +
                std::to_string(announced.width) + "x" + std::to_string(announced.height));
  }
  // The announcement comes from the network too. A frame must also fit the protocol
  // uncompressed; only RVL could carry a larger one, and RVL codes a field of zeros of any size
  // in a few bytes.
  const std::size_t pixels = std::size_t{header.width} * header.height;
  const std::size_t bytesPerPixel = frame->hasConfidence ? 3 : 2;
  if (bytesPerPixel * pixels > protocol::kMaxPayloadBytes) {
    return Fail("bad range frame: " + std::to_string(header.width) + "x" +
                std::to_string(header.height) + ", more than the " +
                std::to_string(protocol::kMaxPayloadBytes / bytesPerPixel) +
                " pixels a range frame carries");
  }
  ReceivedFrame received;
  received.header = header;
  received.depth.resize(pixels);
  if (const auto ok = protocol::decodeRangeDepth(*frame, received.depth); !ok) {
    return Fail(std::string("bad range frame: ") + ok.error().message);
  }
  if (frame->hasConfidence) {
    received.confidence.resize(pixels);
    if (const auto ok = protocol::decodeRangeConfidence(*frame, received.confidence); !ok) {
      return Fail(std::string("bad range frame: confidence plane: ") + ok.error().message);
    }
  }
  received.wireBytes = protocol::kHeaderBytes + payload.size();
  received.receivedNs = receivedNs;
  return received;
}

}  // namespace smx::host
