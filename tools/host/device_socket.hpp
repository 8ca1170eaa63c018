#pragma once

#include <chrono>
#include <cstddef>
#include <expected>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "smx/net/tcp_client.hpp"
#include "smx/protocol/secure_session.hpp"

// The host's connection to a device: in the clear (a device without an owner), or the owner's
// encrypted channel with a device this host paired with (docs/security.md). Same calls as
// net::TcpClient, so the protocol code above does not know which.
namespace smx::host {

class DeviceSocket {
 public:
  [[nodiscard]] static DeviceSocket plain(net::TcpClient socket);
  // Runs the session handshake; the device must present `deviceKey`. Errors are for the user.
  [[nodiscard]] static std::expected<DeviceSocket, std::string> secure(
      net::TcpClient socket, const protocol::KeyPair& host, const protocol::Key32& deviceKey,
      std::chrono::milliseconds timeout);

  [[nodiscard]] std::expected<void, std::string> sendAll(std::span<const std::byte> bytes,
                                                         std::chrono::milliseconds timeout);
  [[nodiscard]] std::expected<std::size_t, std::string> receiveSome(
      std::span<std::byte> bytes, std::chrono::milliseconds timeout);
  [[nodiscard]] bool encrypted() const { return channel_ != nullptr; }
  void close() { socket_.close(); }

 private:
  DeviceSocket(net::TcpClient socket, std::unique_ptr<protocol::SecureChannel> channel)
      : socket_(std::move(socket)), channel_(std::move(channel)) {}

  net::TcpClient socket_;
  std::unique_ptr<protocol::SecureChannel> channel_;
};

// Reads exactly one clear-text message (handshake or pairing) into `message`: its type and
// payload, or an error for the user. A device's error message is returned as kError.
[[nodiscard]] std::expected<std::pair<protocol::MessageType, std::vector<std::byte>>, std::string>
readClearMessage(net::TcpClient& socket, std::chrono::milliseconds timeout);

}  // namespace smx::host
