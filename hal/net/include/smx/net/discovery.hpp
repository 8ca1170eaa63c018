#pragma once

#include <chrono>
#include <cstdint>
#include <expected>
#include <memory>
#include <string>
#include <vector>

#include "smx/hal/error.hpp"
#include "smx/net/unique_fd.hpp"

// Finding devices on the local network over UDP (docs/protocol.md "Discovery"). A host sends the
// 6-byte request "SMXP?" + version to UDP port 5555, broadcast or to one address; every device
// answers "SMXP!" + version + its TCP port (u16, little-endian) + its board name (u8 length,
// bytes). Anything else is ignored and counted.
namespace smx::net {

inline constexpr std::uint16_t kDiscoveryPort = 5555;

// The device side: answers discovery requests; no heap after create().
class DiscoveryResponder {
 public:
  [[nodiscard]] static std::expected<std::unique_ptr<DiscoveryResponder>, std::string> create(
      const std::string& bindAddress, std::uint16_t udpPort, std::uint16_t tcpPort,
      const std::string& board);

  // Waits at most timeoutNs and answers every request that arrived; returns how many.
  [[nodiscard]] hal::HalResult<int> serviceOnce(std::int64_t timeoutNs);
  [[nodiscard]] std::uint16_t port() const { return port_; }
  [[nodiscard]] std::uint64_t ignored() const { return ignored_; }

 private:
  DiscoveryResponder(UniqueFd socket, std::uint16_t port)
      : socket_(std::move(socket)), port_(port) {}

  UniqueFd socket_;
  std::uint16_t port_;
  std::vector<std::byte> answer_;
  std::uint64_t ignored_ = 0;
};

struct FoundDevice {
  std::string address;  // "HOST:PORT" for --device
  std::string board;
};

// Sends a request to each target ("255.255.255.255" for the local network, or a host) on
// `udpPort` and collects the answers that arrive within `wait`, each device once.
[[nodiscard]] std::expected<std::vector<FoundDevice>, std::string> discoverDevices(
    const std::vector<std::string>& targets, std::uint16_t udpPort, std::chrono::milliseconds wait);

}  // namespace smx::net
