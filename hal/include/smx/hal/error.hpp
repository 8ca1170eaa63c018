#pragma once

#include <cstdint>
#include <expected>

// Failures of the hardware abstraction. Like algo::Error the message is a static string and the
// errno (if any) travels beside it, so building an error never allocates and the steady-state
// loop can report one; the caller adds context when it logs.
namespace smx::hal {

enum class HalErrc : std::uint8_t {
  kTimeout,          // nothing arrived in time (a frame, a client, bytes)
  kDisconnected,     // the device or peer went away; reopen or wait for it
  kBusy,             // every buffer is borrowed, or a second client while one is served
  kInvalidState,     // a call in the wrong state (acquire before start, release twice)
  kInvalidArgument,  // a value the device cannot take (format, size, index)
  kNotSupported,     // the backend cannot do this (a pixel format, a device kind)
  kIo,               // a system call failed for another reason (see sysErrno)
};

struct HalError {
  HalErrc code;
  const char* message;
  int sysErrno = 0;
};

template <class T>
using HalResult = std::expected<T, HalError>;

[[nodiscard]] inline std::unexpected<HalError> halFail(HalErrc code, const char* message,
                                                       int sysErrno = 0) {
  return std::unexpected(HalError{code, message, sysErrno});
}

[[nodiscard]] const char* toString(HalErrc code);

}  // namespace smx::hal
