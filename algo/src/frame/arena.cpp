#include "smx/algo/arena.hpp"

#include <cstdint>

namespace smx::algo {

Result<std::span<std::byte>> Arena::allocateBytes(std::size_t bytes, std::size_t align) {
  if (align == 0 || (align & (align - 1)) != 0) {
    return fail(Errc::kInvalidArgument, "arena alignment is not a power of two");
  }
  // Align the address, not the offset: the caller's buffer may start anywhere.
  const auto base = reinterpret_cast<std::uintptr_t>(buffer_.data());
  const std::uintptr_t mask = align - 1;
  const std::size_t padding = ((base + used_ + mask) & ~mask) - (base + used_);
  const std::size_t free = buffer_.size() - used_;
  if (padding > free || bytes > free - padding) {
    return fail(Errc::kOutOfMemory, "arena exhausted");
  }
  std::byte* start = buffer_.data() + used_ + padding;
  used_ += padding + bytes;
  if (used_ > highWater_) {
    highWater_ = used_;
  }
  return std::span<std::byte>(start, bytes);
}

void Arena::rewind(Marker marker) {
  if (marker.offset <= used_) {
    used_ = marker.offset;
  }
}

}  // namespace smx::algo
