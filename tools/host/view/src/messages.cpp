#include "smx/view/messages.hpp"

#include <cstring>

#include "smx/protocol/rvl.hpp"

namespace smx::view {

namespace {

struct Header {
  MessageKind kind = MessageKind::kDepth;
  std::uint8_t camera = 0;
  int width = 0;
  int height = 0;
  int step = 0;
  std::uint32_t seq = 0;
  std::size_t sizeA = 0;
  std::size_t sizeB = 0;
  std::uint32_t aux = 0;
};

void put16(std::byte* at, std::uint32_t v) {
  at[0] = static_cast<std::byte>(v & 0xFFU);
  at[1] = static_cast<std::byte>((v >> 8U) & 0xFFU);
}

void put32(std::byte* at, std::uint32_t v) {
  put16(at, v & 0xFFFFU);
  put16(at + 2, v >> 16U);
}

void putHeader(std::vector<std::byte>& out, const Header& h) {
  std::byte* at = out.data();
  at[0] = static_cast<std::byte>(h.kind);
  at[1] = static_cast<std::byte>(h.camera);
  put16(at + 2, static_cast<std::uint32_t>(h.width));
  put16(at + 4, static_cast<std::uint32_t>(h.height));
  put16(at + 6, static_cast<std::uint32_t>(h.step));
  put32(at + 8, h.seq);
  put32(at + 12, static_cast<std::uint32_t>(h.sizeA));
  put32(at + 16, static_cast<std::uint32_t>(h.sizeB));
  put32(at + 20, h.aux);
}

// RVL of a plane appended to `out`; the worst case (alternating single zeros and values) is
// under 4 bytes a pixel.
template <class Pixel>
std::size_t appendRvl(std::vector<std::byte>& out, algo::ImageView<const Pixel> plane) {
  if (plane.empty()) {
    return 0;
  }
  const std::size_t start = out.size();
  out.resize(
      start +
      4 * static_cast<std::size_t>(plane.width()) * static_cast<std::size_t>(plane.height()) + 16);
  const auto written = protocol::rvlEncode(plane, std::span(out).subspan(start));
  const std::size_t bytes = written ? *written : 0;  // cannot overflow the bound above
  out.resize(start + bytes);
  return bytes;
}

}  // namespace

std::vector<std::byte> depthMessage(std::uint8_t camera, std::uint32_t seq,
                                    std::uint64_t deviceFrame, algo::ConstDepthPlane depth,
                                    algo::ImageView<const std::uint8_t> confidence) {
  std::vector<std::byte> out(kHeaderBytes);
  const std::size_t depthBytes = appendRvl(out, depth);
  const std::size_t confidenceBytes = appendRvl(out, confidence);
  putHeader(out, {.kind = MessageKind::kDepth,
                  .camera = camera,
                  .width = depth.width(),
                  .height = depth.height(),
                  .step = confidence.empty() || confidence.width() == 0
                              ? 1
                              : depth.width() / confidence.width(),
                  .seq = seq,
                  .sizeA = depthBytes,
                  .sizeB = confidenceBytes,
                  .aux = static_cast<std::uint32_t>(deviceFrame & 0xFFFFFFFFU)});
  return out;
}

std::vector<std::byte> raysMessage(std::uint8_t camera, int width, int height, int step,
                                   std::span<const float> xy) {
  std::vector<std::byte> out(kHeaderBytes + xy.size_bytes());
  std::memcpy(out.data() + kHeaderBytes, xy.data(), xy.size_bytes());  // x86 and ARM: LE
  putHeader(out, {.kind = MessageKind::kRays,
                  .camera = camera,
                  .width = width,
                  .height = height,
                  .step = step,
                  .sizeA = xy.size_bytes()});
  return out;
}

std::vector<std::byte> modelMessage(std::uint32_t seq, std::span<const float> xyz,
                                    std::span<const std::uint8_t> rgb) {
  const std::size_t points = xyz.size() / 3;
  std::vector<std::byte> out(kHeaderBytes + xyz.size_bytes() + rgb.size());
  std::memcpy(out.data() + kHeaderBytes, xyz.data(), xyz.size_bytes());
  std::memcpy(out.data() + kHeaderBytes + xyz.size_bytes(), rgb.data(), rgb.size());
  putHeader(out, {.kind = MessageKind::kModel, .seq = seq, .sizeA = points});
  return out;
}

}  // namespace smx::view
