#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "smx/hal/error.hpp"

// The device end of the network link: it listens and serves one host at a time (a second host
// is refused while one is connected). Byte stream semantics (TCP); the protocol library frames
// messages. Every call is bounded in time and never allocates, so the network thread of the
// firmware stays within the steady state's no-heap rule.
namespace smx::hal {

class Link {
 public:
  virtual ~Link() = default;
  Link(const Link&) = delete;
  Link& operator=(const Link&) = delete;

  // Waits at most timeoutNs for a host; kTimeout if none came.
  [[nodiscard]] virtual HalResult<void> acceptClient(std::int64_t timeoutNs) = 0;
  [[nodiscard]] virtual bool connected() const = 0;
  // Sends what the socket takes now (possibly nothing, possibly part); kDisconnected if the host
  // went away, after which connected() is false.
  [[nodiscard]] virtual HalResult<std::size_t> sendSome(std::span<const std::byte> bytes) = 0;
  // Waits at most timeoutNs for bytes; 0 bytes means none arrived in time.
  [[nodiscard]] virtual HalResult<std::size_t> receiveSome(std::span<std::byte> bytes,
                                                           std::int64_t timeoutNs) = 0;
  // Waits at most timeoutNs until bytes can be received or (with wantWrite) sendSome() can take
  // bytes; also turns away hosts that connect while one is served.
  [[nodiscard]] virtual HalResult<void> waitForIo(bool wantWrite, std::int64_t timeoutNs) = 0;
  virtual void disconnect() = 0;
  [[nodiscard]] virtual std::uint16_t port() const = 0;  // the port it listens on

 protected:
  Link() = default;
};

}  // namespace smx::hal
