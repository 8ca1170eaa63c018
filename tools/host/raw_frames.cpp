#include "raw_frames.hpp"

#include <cstring>

namespace smx::host {

namespace {
using Fail = std::unexpected<std::string>;
}  // namespace

std::expected<RawFrameAssembler, std::string> RawFrameAssembler::create(
    const AnnouncedFrames& announced, std::uint32_t projectorsMask) {
  if (announced.cameras < 1 || announced.width < 1 || announced.height < 1) {
    return Fail("the device announced no camera images to capture");
  }
  const std::size_t pixels = static_cast<std::size_t>(announced.cameras) *
                             static_cast<std::size_t>(announced.width) *
                             static_cast<std::size_t>(announced.height);
  if (pixels > kMaxPixels) {
    return Fail("the device announced " + std::to_string(announced.cameras) + " cameras of " +
                std::to_string(announced.width) + "x" + std::to_string(announced.height) +
                ": more than the " + std::to_string(kMaxPixels) + " pixels a raw capture may hold");
  }
  RawFrameAssembler out;
  out.announced_ = announced;
  out.capture_.projectorsMask = projectorsMask;
  out.capture_.width = announced.width;
  out.capture_.height = announced.height;
  const auto cameraPixels =
      static_cast<std::size_t>(announced.width) * static_cast<std::size_t>(announced.height);
  out.capture_.images.assign(static_cast<std::size_t>(announced.cameras),
                             std::vector<algo::Rgb8>(cameraPixels));
  out.rowSeen_.assign(static_cast<std::size_t>(announced.cameras),
                      std::vector<bool>(static_cast<std::size_t>(announced.height), false));
  out.rowsLeft_ =
      static_cast<std::size_t>(announced.cameras) * static_cast<std::size_t>(announced.height);
  return out;
}

std::expected<void, std::string> RawFrameAssembler::add(std::span<const std::byte> payload) {
  const auto band = protocol::decodeRawFrame(payload);
  if (!band) {
    return Fail(std::string("bad raw frame: ") + band.error().message);
  }
  const protocol::RawFrameHeader& h = band->header;
  if (h.camera >= announced_.cameras) {
    return Fail("raw frame of camera " + std::to_string(h.camera) + ", but the device announced " +
                std::to_string(announced_.cameras) + " cameras");
  }
  if (h.width != announced_.width || h.height != announced_.height) {
    return Fail("raw frame of " + std::to_string(h.width) + "x" + std::to_string(h.height) +
                ", but the device announced " + std::to_string(announced_.width) + "x" +
                std::to_string(announced_.height) + " images");
  }
  if (h.projectorsMask != capture_.projectorsMask) {
    return Fail("raw frame lit by projectors " + std::to_string(h.projectorsMask) +
                " (bit mask), but " + std::to_string(capture_.projectorsMask) + " was asked for");
  }
  if (haveCaptureNumber_ && h.capture != capture_.capture) {
    return Fail("raw frame bands of two captures (" + std::to_string(capture_.capture) + " and " +
                std::to_string(h.capture) + ")");
  }
  std::vector<bool>& seen = rowSeen_[h.camera];
  for (int r = h.firstRow; r < h.firstRow + h.rows; ++r) {
    if (seen[static_cast<std::size_t>(r)]) {
      return Fail("raw frame: row " + std::to_string(r) + " of camera " + std::to_string(h.camera) +
                  " sent twice");
    }
  }
  for (int r = h.firstRow; r < h.firstRow + h.rows; ++r) {
    seen[static_cast<std::size_t>(r)] = true;
  }
  haveCaptureNumber_ = true;
  capture_.capture = h.capture;
  rowsLeft_ -= h.rows;
  // decodeRawFrame checked rows × width × 3 bytes inside the frame, and the frame is the
  // announced one: the band lands inside the image allocated for it.
  std::memcpy(capture_.images[h.camera].data() + std::size_t{h.firstRow} * h.width,
              band->pixels.data(), band->pixels.size());
  return {};
}

}  // namespace smx::host
