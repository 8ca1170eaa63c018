#include "smx/protocol/rvl.hpp"

#include <limits>

namespace smx::protocol {

namespace {

// 3 data bits per nibble: 11 nibbles hold any 32-bit count, 6 any zigzag-coded 16-bit difference.
constexpr int kMaxNibbles = 11;

class NibbleWriter {
 public:
  explicit NibbleWriter(std::span<std::byte> out) : out_(out) {}

  void putCode(std::uint32_t value) {
    do {
      std::uint32_t nibble = value & 0x7U;
      value >>= 3;
      if (value != 0) {
        nibble |= 0x8U;
      }
      putNibble(nibble);
    } while (value != 0);
  }

  // Pads the last byte; returns the bytes written, or -1 when `out` was too small.
  [[nodiscard]] std::ptrdiff_t finish() {
    if (high_) {
      putNibble(0);
    }
    return overflow_ ? -1 : static_cast<std::ptrdiff_t>(used_);
  }

 private:
  void putNibble(std::uint32_t nibble) {
    if (overflow_) {
      return;
    }
    if (!high_) {
      if (used_ == out_.size()) {
        overflow_ = true;
        return;
      }
      out_[used_] = static_cast<std::byte>(nibble << 4);
      high_ = true;
    } else {
      out_[used_] |= static_cast<std::byte>(nibble);
      ++used_;
      high_ = false;
    }
  }

  std::span<std::byte> out_;
  std::size_t used_ = 0;
  bool high_ = false;  // a byte is half written
  bool overflow_ = false;
};

class NibbleReader {
 public:
  explicit NibbleReader(std::span<const std::byte> in) : in_(in) {}

  // False on truncated input or a code too long for 32 bits.
  [[nodiscard]] bool getCode(std::uint32_t& value) {
    std::uint64_t result = 0;
    for (int i = 0; i < kMaxNibbles; ++i) {
      if (nibblesUsed_ >= 2 * in_.size()) {
        return false;
      }
      const auto byte = std::to_integer<std::uint32_t>(in_[nibblesUsed_ / 2]);
      const std::uint32_t nibble = (nibblesUsed_ % 2 == 0) ? byte >> 4 : byte & 0xFU;
      ++nibblesUsed_;
      result |= static_cast<std::uint64_t>(nibble & 0x7U) << (3 * i);
      if ((nibble & 0x8U) == 0) {
        if (result > 0xFFFFFFFFU) {
          return false;
        }
        value = static_cast<std::uint32_t>(result);
        return true;
      }
    }
    return false;
  }

  // True when only the padding nibble (zero) of the last byte is left.
  [[nodiscard]] bool atEnd() const {
    const std::size_t total = 2 * in_.size();
    if (nibblesUsed_ == total) {
      return true;
    }
    return nibblesUsed_ + 1 == total && (std::to_integer<unsigned>(in_.back()) & 0xFU) == 0;
  }

 private:
  std::span<const std::byte> in_;
  std::size_t nibblesUsed_ = 0;
};

constexpr std::uint32_t zigzag(std::int32_t delta) {
  return (static_cast<std::uint32_t>(delta) << 1) ^ static_cast<std::uint32_t>(delta >> 31);
}

constexpr std::int32_t unzigzag(std::uint32_t code) {
  return static_cast<std::int32_t>(code >> 1) ^ -static_cast<std::int32_t>(code & 1U);
}

template <class Pixel>
ProtocolResult<std::size_t> encodePlane(algo::ImageView<const Pixel> depth,
                                        std::span<std::byte> out) {
  NibbleWriter writer(out);
  std::int32_t previous = 0;
  std::uint32_t zeros = 0;
  // Runs continue across rows: the image is one sequence in row order.
  const int width = depth.width();
  int x = 0;
  int y = 0;
  const auto at = [&](int px, int py) { return depth.rowPtr(py)[px]; };
  const auto advance = [&] {
    if (++x == width) {
      x = 0;
      ++y;
    }
  };
  const int height = depth.empty() ? 0 : depth.height();
  while (y < height) {
    zeros = 0;
    while (y < height && at(x, y) == 0) {
      ++zeros;
      advance();
    }
    // Count the non-zero run, then write the codes of its values.
    const int runX = x;
    const int runY = y;
    std::uint32_t nonZeros = 0;
    while (y < height && at(x, y) != 0) {
      ++nonZeros;
      advance();
    }
    writer.putCode(zeros);
    writer.putCode(nonZeros);
    x = runX;
    y = runY;
    for (std::uint32_t i = 0; i < nonZeros; ++i) {
      const std::int32_t value = at(x, y);
      writer.putCode(zigzag(value - previous));
      previous = value;
      advance();
    }
  }
  const std::ptrdiff_t bytes = writer.finish();
  if (bytes < 0) {
    return protocolFail(ProtocolErrc::kBufferTooSmall, "RVL output does not fit its buffer");
  }
  return static_cast<std::size_t>(bytes);
}

template <class Pixel>
ProtocolResult<void> decodePlane(std::span<const std::byte> in, std::span<Pixel> out) {
  constexpr std::int64_t kMaxValue = std::numeric_limits<Pixel>::max();
  NibbleReader reader(in);
  std::size_t filled = 0;
  std::int32_t previous = 0;
  while (filled < out.size()) {
    std::uint32_t zeros = 0;
    std::uint32_t nonZeros = 0;
    if (!reader.getCode(zeros) || !reader.getCode(nonZeros)) {
      return protocolFail(ProtocolErrc::kMalformed, "RVL data ends before the image is complete");
    }
    const std::size_t left = out.size() - filled;
    if (zeros > left || nonZeros > left - zeros) {
      return protocolFail(ProtocolErrc::kMalformed, "RVL run goes past the end of the image");
    }
    if (zeros == 0 && nonZeros == 0) {
      return protocolFail(ProtocolErrc::kMalformed, "RVL run pair of length zero");
    }
    for (std::uint32_t i = 0; i < zeros; ++i) {
      out[filled++] = 0;
    }
    for (std::uint32_t i = 0; i < nonZeros; ++i) {
      std::uint32_t code = 0;
      if (!reader.getCode(code)) {
        return protocolFail(ProtocolErrc::kMalformed, "RVL data ends inside a run of values");
      }
      const std::int64_t value = std::int64_t{previous} + unzigzag(code);
      if (value <= 0 || value > kMaxValue) {
        return protocolFail(ProtocolErrc::kMalformed, kMaxValue == 0xFF
                                                          ? "RVL value outside 1..255"
                                                          : "RVL value outside 1..65535");
      }
      previous = static_cast<std::int32_t>(value);
      out[filled++] = static_cast<Pixel>(value);
    }
  }
  if (!reader.atEnd()) {
    return protocolFail(ProtocolErrc::kMalformed, "RVL data continues after the image");
  }
  return {};
}

}  // namespace

ProtocolResult<std::size_t> rvlEncode(algo::ConstDepthPlane depth, std::span<std::byte> out) {
  return encodePlane(depth, out);
}

ProtocolResult<std::size_t> rvlEncode(algo::ImageView<const std::uint8_t> plane,
                                      std::span<std::byte> out) {
  return encodePlane(plane, out);
}

ProtocolResult<void> rvlDecode(std::span<const std::byte> in, std::span<std::uint16_t> out) {
  return decodePlane(in, out);
}

ProtocolResult<void> rvlDecode(std::span<const std::byte> in, std::span<std::uint8_t> out) {
  return decodePlane(in, out);
}

}  // namespace smx::protocol
