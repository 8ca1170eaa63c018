#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "smx/algo/range_image.hpp"

// The live view's binary WebSocket messages (docs/live-view.md). Every message starts with the
// same 24-byte little-endian header; the page (web/view.js) reads exactly this layout.
//   u8 kind, u8 camera, u16 width, u16 height, u16 step, u32 seq, u32 sizeA, u32 sizeB, u32 aux
namespace smx::view {

enum class MessageKind : std::uint8_t {
  kDepth = 1,  // sizeA bytes of RVL depth, then sizeB bytes of RVL confidence (0: none) of
               // width/step × height/step pixels; aux = the device's frame number (low 32 bits)
  kRays = 2,   // the camera's undistorted rays (x/z, y/z) every `step` pixels: float32 pairs,
               // row by row, sizeA bytes
  kModel = 3,  // sizeA points: float32 x, y, z (metres, model frame), then sizeA × u8 r, g, b
};

inline constexpr std::size_t kHeaderBytes = 24;

// A depth frame: RVL-coded depth (and confidence when not empty, of the depth's size divided by
// a whole step), the project's own depth codec (docs/protocol.md), which the page decodes.
[[nodiscard]] std::vector<std::byte> depthMessage(std::uint8_t camera, std::uint32_t seq,
                                                  std::uint64_t deviceFrame,
                                                  algo::ConstDepthPlane depth,
                                                  algo::ImageView<const std::uint8_t> confidence);

// A camera's rays for the point cloud: xy holds (x/z, y/z) of every step-th pixel in x and y.
[[nodiscard]] std::vector<std::byte> raysMessage(std::uint8_t camera, int width, int height,
                                                 int step, std::span<const float> xy);

// Points (x, y, z interleaved) and their colours (r, g, b interleaved, 0…255).
[[nodiscard]] std::vector<std::byte> modelMessage(std::uint32_t seq, std::span<const float> xyz,
                                                  std::span<const std::uint8_t> rgb);

}  // namespace smx::view
