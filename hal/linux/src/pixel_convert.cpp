#include "smx/linux/pixel_convert.hpp"

namespace smx::lnx {

namespace {

using hal::HalErrc;
using hal::halFail;

hal::HalResult<void> checkSource(std::span<const std::byte> src, std::ptrdiff_t srcStrideBytes,
                                 std::ptrdiff_t rowBytes, int height) {
  if (srcStrideBytes < rowBytes) {
    return halFail(HalErrc::kInvalidArgument, "source stride is smaller than a row");
  }
  if (src.size() < sourceBytesNeeded(srcStrideBytes, rowBytes, height)) {
    return halFail(HalErrc::kInvalidArgument, "source is smaller than the frame");
  }
  return {};
}

std::uint8_t byteAt(const std::byte* row, std::ptrdiff_t i) {
  return std::to_integer<std::uint8_t>(row[i]);
}

}  // namespace

hal::HalResult<void> convertYuyvToRgb(std::span<const std::byte> src, std::ptrdiff_t srcStrideBytes,
                                      const algo::RgbView& dst) {
  const int width = dst.width();
  if (width % 2 != 0) {
    return halFail(HalErrc::kInvalidArgument, "YUYV needs an even width");
  }
  const std::ptrdiff_t rowBytes = std::ptrdiff_t{2} * width;
  if (auto ok = checkSource(src, srcStrideBytes, rowBytes, dst.height()); !ok) {
    return ok;
  }
  for (int y = 0; y < dst.height(); ++y) {
    const std::byte* in = src.data() + srcStrideBytes * y;
    algo::Rgb8* out = dst.rowPtr(y);
    for (std::ptrdiff_t x = 0; x < width; x += 2) {
      const std::ptrdiff_t i = 2 * x;  // Y0 U Y1 V
      const std::uint8_t u = byteAt(in, i + 1);
      const std::uint8_t v = byteAt(in, i + 3);
      out[x] = yuvToRgb(byteAt(in, i), u, v);
      out[x + 1] = yuvToRgb(byteAt(in, i + 2), u, v);
    }
  }
  return {};
}

hal::HalResult<void> convertBgr24ToRgb(std::span<const std::byte> src,
                                       std::ptrdiff_t srcStrideBytes, const algo::RgbView& dst) {
  const std::ptrdiff_t rowBytes = std::ptrdiff_t{3} * dst.width();
  if (auto ok = checkSource(src, srcStrideBytes, rowBytes, dst.height()); !ok) {
    return ok;
  }
  for (int y = 0; y < dst.height(); ++y) {
    const std::byte* in = src.data() + srcStrideBytes * y;
    algo::Rgb8* out = dst.rowPtr(y);
    for (std::ptrdiff_t x = 0; x < dst.width(); ++x) {
      out[x] = {.r = byteAt(in, 3 * x + 2), .g = byteAt(in, 3 * x + 1), .b = byteAt(in, 3 * x)};
    }
  }
  return {};
}

}  // namespace smx::lnx
