#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

#include "smx/algo/error.hpp"

namespace smx::algo {

// One 8-bit RGB pixel as V4L2 RGB24 lays it out in memory (r, g, b).
struct Rgb8 {
  std::uint8_t r;
  std::uint8_t g;
  std::uint8_t b;
  friend constexpr bool operator==(Rgb8, Rgb8) = default;
};
static_assert(sizeof(Rgb8) == 3 && alignof(Rgb8) == 1);

namespace detail {
template <class From, class To>
concept AddsConstTo = std::is_same_v<const From, To> && !std::is_same_v<From, To>;
}  // namespace detail

// Non-owning view of a 2-D image of Pixel with a row stride in bytes. Rows may be padded (V4L2
// bytesperline need not be a multiple of the pixel size times the width). Pixel may be const for
// read-only views; a mutable view converts to a const one.
template <class Pixel>
class ImageView {
 public:
  using Byte = std::conditional_t<std::is_const_v<Pixel>, const std::byte, std::byte>;

  constexpr ImageView() = default;

  // Checks what the constructor cannot: the stride holds a row and keeps rows aligned for Pixel.
  [[nodiscard]] static Result<ImageView> create(Byte* data, int width, int height,
                                                std::ptrdiff_t strideBytes) {
    if (width < 0 || height < 0) {
      return fail(Errc::kInvalidArgument, "image size is negative");
    }
    if (strideBytes < static_cast<std::ptrdiff_t>(sizeof(Pixel)) * width) {
      return fail(Errc::kSizeMismatch, "image stride is smaller than a row");
    }
    if (strideBytes % static_cast<std::ptrdiff_t>(alignof(Pixel)) != 0 ||
        reinterpret_cast<std::uintptr_t>(data) % alignof(Pixel) != 0) {
      return fail(Errc::kInvalidArgument, "image data or stride is misaligned for the pixel type");
    }
    if (data == nullptr && width > 0 && height > 0) {
      return fail(Errc::kInvalidArgument, "image data is null");
    }
    return ImageView(data, width, height, strideBytes);
  }

  // A tightly packed image over a span; the span must hold exactly width*height pixels.
  [[nodiscard]] static Result<ImageView> packed(std::span<Pixel> pixels, int width, int height) {
    if (width < 0 || height < 0 ||
        pixels.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
      return fail(Errc::kSizeMismatch, "pixel buffer size does not match width*height");
    }
    return ImageView(reinterpret_cast<Byte*>(pixels.data()), width, height,
                     static_cast<std::ptrdiff_t>(sizeof(Pixel)) * width);
  }

  // Implicit on purpose: a mutable view is usable wherever a const one is expected.
  template <detail::AddsConstTo<Pixel> Other>
  constexpr ImageView(const ImageView<Other>& other)  // NOLINT(google-explicit-constructor)
      : data_(other.bytes()),
        width_(other.width()),
        height_(other.height()),
        strideBytes_(other.strideBytes()) {}

  [[nodiscard]] constexpr int width() const { return width_; }
  [[nodiscard]] constexpr int height() const { return height_; }
  [[nodiscard]] constexpr std::ptrdiff_t strideBytes() const { return strideBytes_; }
  [[nodiscard]] constexpr bool empty() const { return width_ == 0 || height_ == 0; }
  [[nodiscard]] constexpr Byte* bytes() const { return data_; }

  [[nodiscard]] Pixel* rowPtr(int y) const {
    assert(y >= 0 && y < height_);
    return reinterpret_cast<Pixel*>(data_ + static_cast<std::ptrdiff_t>(y) * strideBytes_);
  }
  [[nodiscard]] std::span<Pixel> row(int y) const {
    return {rowPtr(y), static_cast<std::size_t>(width_)};
  }
  [[nodiscard]] Pixel& operator()(int x, int y) const {
    assert(x >= 0 && x < width_);
    return rowPtr(y)[x];
  }

  // The rectangle [x, x+w) × [y, y+h), clipped to the image.
  [[nodiscard]] ImageView sub(int x, int y, int w, int h) const {
    const int x0 = clamp(x, 0, width_);
    const int y0 = clamp(y, 0, height_);
    const int x1 = clamp(x + w, x0, width_);
    const int y1 = clamp(y + h, y0, height_);
    return ImageView(
        data_ + static_cast<std::ptrdiff_t>(y0) * strideBytes_ +
            static_cast<std::ptrdiff_t>(x0) * static_cast<std::ptrdiff_t>(sizeof(Pixel)),
        x1 - x0, y1 - y0, strideBytes_);
  }

 private:
  constexpr ImageView(Byte* data, int width, int height, std::ptrdiff_t strideBytes)
      : data_(data), width_(width), height_(height), strideBytes_(strideBytes) {}

  static constexpr int clamp(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

  Byte* data_ = nullptr;
  int width_ = 0;
  int height_ = 0;
  std::ptrdiff_t strideBytes_ = 0;
};

using RgbView = ImageView<Rgb8>;
using ConstRgbView = ImageView<const Rgb8>;
using PlaneS16 = ImageView<std::int16_t>;
using ConstPlaneS16 = ImageView<const std::int16_t>;
using PlaneS32 = ImageView<std::int32_t>;
using ConstPlaneS32 = ImageView<const std::int32_t>;

}  // namespace smx::algo
