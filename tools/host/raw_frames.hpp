#pragma once

#include <cstdint>
#include <expected>
#include <span>
#include <string>
#include <vector>

#include "range_frame.hpp"
#include "smx/algo/image_view.hpp"

// The raw-frame bands of one raw capture (docs/protocol.md, "Raw capture"), put together into one
// RGB8 image per camera. Every band comes from the network, so its camera, frame size, lit
// projectors and capture number are checked against the announcement and the request before a
// byte is copied; the images are allocated once, at the announced size.
namespace smx::host {

struct RawCapture {
  std::uint32_t projectorsMask = 0;
  std::uint64_t capture = 0;                    // the device's raw capture number
  std::vector<std::vector<algo::Rgb8>> images;  // per camera, width × height, row by row
  int width = 0;
  int height = 0;
};

class RawFrameAssembler {
 public:
  // The most pixels one raw capture may hold over all cameras (8-bit RGB: 3 bytes each); a
  // device announcing more is refused before anything is allocated.
  static constexpr std::size_t kMaxPixels = std::size_t{1} << 26U;

  [[nodiscard]] static std::expected<RawFrameAssembler, std::string> create(
      const AnnouncedFrames& announced, std::uint32_t projectorsMask);

  // Adds one band (a kRawFrame payload, without the message header).
  [[nodiscard]] std::expected<void, std::string> add(std::span<const std::byte> payload);
  [[nodiscard]] bool complete() const { return rowsLeft_ == 0; }
  // The capture, once complete().
  [[nodiscard]] RawCapture take() { return std::move(capture_); }

 private:
  RawFrameAssembler() = default;

  AnnouncedFrames announced_;
  RawCapture capture_;
  std::vector<std::vector<bool>> rowSeen_;  // per camera, per row
  std::size_t rowsLeft_ = 0;
  bool haveCaptureNumber_ = false;
};

}  // namespace smx::host
