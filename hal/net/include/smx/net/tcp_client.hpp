#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <span>
#include <string>

#include "smx/hal/unique_fd.hpp"

// The host end of the link: a TCP connection to a device. Host tool code: errors are messages
// that name the device and the system's reason.
namespace smx::net {

struct DeviceAddress {
  std::string host;  // a name, an IPv4 address or an IPv6 address without brackets
  std::uint16_t port = 0;
};

// "HOST", "HOST:PORT", "[V6]", "[V6]:PORT" or a bare IPv6 address ("::1", "fe80::1%eth0";
// more than one colon, so a port needs the brackets); defaultPort when none is given.
[[nodiscard]] std::expected<DeviceAddress, std::string> parseDeviceAddress(
    const std::string& text, std::uint16_t defaultPort);
// "host:port", or "[v6]:port" for an IPv6 address: what a user can pass back to --device.
[[nodiscard]] std::string toString(const DeviceAddress& address);

class TcpClient {
 public:
  // Tries each address the host resolves to (IPv6 and IPv4) in the resolver's order.
  // receiveBufferBytes > 0 caps the kernel's receive buffer: a host that falls behind then
  // holds back the device, which drops its oldest frames, instead of collecting stale ones.
  [[nodiscard]] static std::expected<TcpClient, std::string> connect(
      const DeviceAddress& address, std::chrono::milliseconds timeout, int receiveBufferBytes = 0);

  // Sends everything or fails (peer closed, timeout while the peer reads nothing).
  [[nodiscard]] std::expected<void, std::string> sendAll(std::span<const std::byte> bytes,
                                                         std::chrono::milliseconds timeout);
  // Waits at most `timeout`; 0 bytes: nothing arrived in time. Closed by the peer: an error.
  [[nodiscard]] std::expected<std::size_t, std::string> receiveSome(
      std::span<std::byte> bytes, std::chrono::milliseconds timeout);
  void close() { fd_.reset(); }

 private:
  explicit TcpClient(hal::UniqueFd fd) : fd_(std::move(fd)) {}
  hal::UniqueFd fd_;
};

}  // namespace smx::net
