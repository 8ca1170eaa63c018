#pragma once

#include <cstddef>
#include <span>
#include <type_traits>

#include "smx/algo/error.hpp"
#include "smx/algo/image_view.hpp"

namespace smx::algo {

// Carves working memory out of one caller-provided buffer: the pipeline sizes everything at init
// and never touches the heap afterwards. A bump allocator: allocations are released together by
// rewinding to a marker (per-frame scratch) or by dropping the arena. It never owns the buffer.
//
// Only trivially copyable, trivially destructible types are handed out (no destructors run); the
// memory is not initialised.
class Arena {
 public:
  // Image rows are padded to this many bytes so SIMD variants can load whole rows aligned.
  static constexpr std::size_t kRowAlignBytes = 16;

  struct Marker {
    std::size_t offset;
  };

  explicit Arena(std::span<std::byte> buffer) : buffer_(buffer) {}
  Arena(const Arena&) = delete;
  Arena& operator=(const Arena&) = delete;

  [[nodiscard]] Result<std::span<std::byte>> allocateBytes(std::size_t bytes, std::size_t align);

  template <class T>
  requires(std::is_trivially_copyable_v<T>&& std::is_trivially_destructible_v<T>)
      [[nodiscard]] Result<std::span<T>> allocate(std::size_t count) {
    if (count > kMaxBytes / sizeof(T)) {
      return fail(Errc::kOutOfMemory, "arena request overflows");
    }
    auto bytes = allocateBytes(count * sizeof(T), alignof(T));
    if (!bytes) {
      return std::unexpected(bytes.error());
    }
    return std::span<T>(reinterpret_cast<T*>(bytes->data()), count);
  }

  // A width × height image whose rows start kRowAlignBytes-aligned.
  template <class Pixel>
  [[nodiscard]] Result<ImageView<Pixel>> allocateImage(int width, int height) {
    if (width < 0 || height < 0) {
      return fail(Errc::kInvalidArgument, "image size is negative");
    }
    const std::size_t stride = roundUp(sizeof(Pixel) * static_cast<std::size_t>(width));
    if (height > 0 && stride > kMaxBytes / static_cast<std::size_t>(height)) {
      return fail(Errc::kOutOfMemory, "arena request overflows");
    }
    auto bytes = allocateBytes(stride * static_cast<std::size_t>(height), kRowAlignBytes);
    if (!bytes) {
      return std::unexpected(bytes.error());
    }
    return ImageView<Pixel>::create(bytes->data(), width, height,
                                    static_cast<std::ptrdiff_t>(stride));
  }

  [[nodiscard]] Marker mark() const { return Marker{used_}; }
  // Releases everything allocated after the marker was taken.
  void rewind(Marker marker);

  [[nodiscard]] std::size_t capacity() const { return buffer_.size(); }
  [[nodiscard]] std::size_t used() const { return used_; }
  // The most bytes ever in use at once, alignment padding included: the buffer size the same
  // sequence of allocations needs.
  [[nodiscard]] std::size_t highWater() const { return highWater_; }

 private:
  static constexpr std::size_t kMaxBytes = static_cast<std::size_t>(PTRDIFF_MAX);
  static constexpr std::size_t roundUp(std::size_t n) {
    return (n + kRowAlignBytes - 1) / kRowAlignBytes * kRowAlignBytes;
  }

  std::span<std::byte> buffer_;
  std::size_t used_ = 0;
  std::size_t highWater_ = 0;
};

// Sizes a sequence of allocations without memory: the same calls as Arena, returning empty spans
// and views, and the buffer size that makes them succeed wherever the buffer starts (each
// allocation counted with its worst-case alignment padding). Lets a stage report the scratch it
// needs by running its own allocation code.
class ArenaSizer {
 public:
  template <class T>
  [[nodiscard]] Result<std::span<T>> allocate(std::size_t count) {
    bytes_ += count * sizeof(T) + alignof(T) - 1;
    return std::span<T>();
  }
  template <class Pixel>
  [[nodiscard]] Result<ImageView<Pixel>> allocateImage(int width, int height) {
    const std::size_t stride =
        (sizeof(Pixel) * static_cast<std::size_t>(width) + Arena::kRowAlignBytes - 1) /
        Arena::kRowAlignBytes * Arena::kRowAlignBytes;
    bytes_ += stride * static_cast<std::size_t>(height) + Arena::kRowAlignBytes - 1;
    return ImageView<Pixel>();
  }
  [[nodiscard]] std::size_t bytes() const { return bytes_; }

 private:
  std::size_t bytes_ = 0;
};

// Carving helpers for stages that run the same allocation code on an ArenaSizer (to report their
// size) and on an Arena (to take the memory): each fills `out` or returns the error.
template <class T, class Carver>
[[nodiscard]] Result<void> carveSpan(Carver& carver, std::span<T>& out, std::size_t count) {
  auto span = carver.template allocate<T>(count);
  if (!span) {
    return std::unexpected(span.error());
  }
  out = *span;
  return {};
}

template <class Pixel, class Carver>
[[nodiscard]] Result<void> carveImage(Carver& carver, ImageView<Pixel>& out, int width,
                                      int height) {
  auto view = carver.template allocateImage<Pixel>(width, height);
  if (!view) {
    return std::unexpected(view.error());
  }
  out = *view;
  return {};
}

}  // namespace smx::algo
