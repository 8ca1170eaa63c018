#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "smx/algo/range_image.hpp"
#include "smx/protocol/wire.hpp"

// RVL, the lossless depth-image codec of A. D. Wilson, "Fast Lossless Depth Image Compression"
// (ISS 2017), as stripemux sends it (docs/protocol.md): the image row by row as alternating runs
// of zeros and of non-zero values; each non-zero value as the zigzag-coded difference to the
// previous non-zero value; every count and difference as a variable-length code of 4-bit
// nibbles (3 data bits, high bit = more follows, least significant group first), nibbles packed
// high then low into bytes, the last byte padded with a zero nibble. 8-bit planes (confidence)
// are coded the same way, their values limited to 1…255. Integer-only, no heap.
namespace smx::protocol {

// Compresses into `out`; kBufferTooSmall when it does not fit (then send it raw).
[[nodiscard]] ProtocolResult<std::size_t> rvlEncode(algo::ConstDepthPlane depth,
                                                    std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::size_t> rvlEncode(algo::ImageView<const std::uint8_t> plane,
                                                    std::span<std::byte> out);
// Expands exactly out.size() values; kMalformed for truncated input, runs past the image's end,
// values above 16 bits, codes longer than needed for 32 bits, a run pair that makes no progress,
// or bytes left over.
[[nodiscard]] ProtocolResult<void> rvlDecode(std::span<const std::byte> in,
                                             std::span<std::uint16_t> out);
[[nodiscard]] ProtocolResult<void> rvlDecode(std::span<const std::byte> in,
                                             std::span<std::uint8_t> out);

}  // namespace smx::protocol
