// libFuzzer target for PNG input (smx::sim::readPngRgb8 and readPngGray16 on bytes in memory,
// which the file readers use): any bytes are an image within the size limit or an error, never
// a crash, a sanitizer report or an allocation beyond the limit (run-fuzz sets a malloc limit).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "smx/sim/png_io.hpp"

namespace {

// Small enough that every accepted image decodes in milliseconds (3 MiB as RGB).
constexpr smx::sim::PngSizeLimit kLimit{.maxSide = 4096, .maxPixels = std::uint64_t{1} << 20U};

template <class Image>
void check(const Image& image) {
  if (image.width < 1 || image.height < 1 || image.width > kLimit.maxSide ||
      image.height > kLimit.maxSide ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height ||
      image.pixels.size() > kLimit.maxPixels) {
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto bytes = std::as_bytes(std::span(data, size));
  if (const auto rgb = smx::sim::readPngRgb8(bytes, "fuzz.png", kLimit)) {
    check(*rgb);
  }
  if (const auto grey = smx::sim::readPngGray16(bytes, "fuzz.png", kLimit)) {
    check(*grey);
  }
  return 0;
}
