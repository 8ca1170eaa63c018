#pragma once

#include <cstdint>
#include <expected>

namespace smx::algo {

// Failure kinds of the algorithm library. The message is a static string: building an error never
// allocates, so errors are usable on the per-frame path.
enum class Errc : std::uint8_t {
  kInvalidArgument,
  kSizeMismatch,
  kOutOfMemory,
  kNotFound,
};

struct Error {
  Errc code;
  const char* message;
};

template <class T>
using Result = std::expected<T, Error>;

[[nodiscard]] inline std::unexpected<Error> fail(Errc code, const char* message) {
  return std::unexpected(Error{code, message});
}

}  // namespace smx::algo
