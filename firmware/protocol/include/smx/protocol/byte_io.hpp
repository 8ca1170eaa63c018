#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>
#include <type_traits>

// Little-endian fields in and out of byte buffers, bounds-checked: a writer that runs out of room
// and a reader that runs past the end both latch a failure flag instead of touching memory
// outside the buffer, so a message is checked once at the end. Never allocates.
namespace smx::protocol {

class ByteWriter {
 public:
  explicit ByteWriter(std::span<std::byte> out) : out_(out) {}

  template <class T>
  requires std::is_unsigned_v<T>
  void put(T value) {
    std::byte* at = reserve(sizeof(T));
    if (at == nullptr) {
      return;
    }
    for (std::size_t i = 0; i < sizeof(T); ++i) {
      at[i] = static_cast<std::byte>((std::uint64_t{value} >> (8 * i)) & 0xFFU);
    }
  }
  void putBytes(std::span<const std::byte> bytes) {
    std::byte* at = reserve(bytes.size());
    if (at != nullptr && !bytes.empty()) {
      std::memcpy(at, bytes.data(), bytes.size());
    }
  }
  // A string with a 16-bit (short) or 32-bit (long) length prefix.
  void putString16(std::string_view text);
  void putString32(std::string_view text);

  // Room left for writing directly (compressors); advance() then claims what was written.
  [[nodiscard]] std::span<std::byte> remaining() const { return out_.subspan(used_); }
  void advance(std::size_t bytes) { (void)reserve(bytes); }

  [[nodiscard]] std::size_t size() const { return used_; }
  [[nodiscard]] bool ok() const { return ok_; }

 private:
  std::byte* reserve(std::size_t bytes) {
    if (!ok_ || out_.size() - used_ < bytes) {
      ok_ = false;
      return nullptr;
    }
    std::byte* at = out_.data() + used_;
    used_ += bytes;
    return at;
  }

  std::span<std::byte> out_;
  std::size_t used_ = 0;
  bool ok_ = true;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::byte> in) : in_(in) {}

  template <class T>
  requires std::is_unsigned_v<T>
  [[nodiscard]] T get() {
    const std::byte* at = take(sizeof(T));
    if (at == nullptr) {
      return 0;
    }
    T value = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) {
      value = static_cast<T>(value | static_cast<T>(std::to_integer<T>(at[i]) << (8 * i)));
    }
    return value;
  }
  [[nodiscard]] std::span<const std::byte> getBytes(std::size_t count) {
    const std::byte* at = take(count);
    return at == nullptr ? std::span<const std::byte>{} : std::span(at, count);
  }
  [[nodiscard]] std::string_view getString16() { return asText(getBytes(get<std::uint16_t>())); }
  [[nodiscard]] std::string_view getString32() { return asText(getBytes(get<std::uint32_t>())); }
  [[nodiscard]] std::span<const std::byte> rest() { return getBytes(in_.size() - used_); }

  [[nodiscard]] bool ok() const { return ok_; }
  [[nodiscard]] bool atEnd() const { return used_ == in_.size(); }

 private:
  const std::byte* take(std::size_t bytes) {
    if (!ok_ || in_.size() - used_ < bytes) {
      ok_ = false;
      return nullptr;
    }
    const std::byte* at = in_.data() + used_;
    used_ += bytes;
    return at;
  }
  static std::string_view asText(std::span<const std::byte> bytes) {
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
  }

  std::span<const std::byte> in_;
  std::size_t used_ = 0;
  bool ok_ = true;
};

inline void ByteWriter::putString16(std::string_view text) {
  if (text.size() > 0xFFFFU) {
    ok_ = false;
    return;
  }
  put(static_cast<std::uint16_t>(text.size()));
  putBytes(std::as_bytes(std::span(text.data(), text.size())));
}

inline void ByteWriter::putString32(std::string_view text) {
  if (text.size() > 0xFFFFFFFFU) {
    ok_ = false;
    return;
  }
  put(static_cast<std::uint32_t>(text.size()));
  putBytes(std::as_bytes(std::span(text.data(), text.size())));
}

}  // namespace smx::protocol
