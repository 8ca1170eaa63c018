#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <memory>
#include <string>
#include <vector>

#include "smx/hal/error.hpp"
#include "smx/hal/unique_fd.hpp"

// Finding devices on the local network over UDP (docs/protocol.md "Discovery"). A host sends the
// request "SMXP?" + version, zero-padded to kDiscoveryRequestBytes, to UDP port 5555, broadcast
// or to one address; every device answers "SMXP!" + version + its TCP port (u16, little-endian)
// + its board name (u8 length, bytes). A device answers no request shorter than its answer, so
// a forged source address cannot make it an amplifier, and it answers at most
// kDiscoveryRepliesPerSource per second to one address and kDiscoveryRepliesTotal per second in
// all. Anything else is ignored and counted.
namespace smx::net {

inline constexpr std::uint16_t kDiscoveryPort = 5555;
// The longest answer: tag, version, port, name length and a 255-byte name.
inline constexpr std::size_t kDiscoveryRequestBytes = 5 + 1 + 2 + 1 + 255;
// A host asks once per run (a person typing `stripemux`): a few a second per address is plenty,
// and a forged flood gets back no more than it sent, at most this often.
inline constexpr int kDiscoveryRepliesPerSource = 4;
inline constexpr int kDiscoveryRepliesTotal = 32;

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
  // Requests not answered because of the rate limits.
  [[nodiscard]] std::uint64_t limited() const { return limited_; }

 private:
  // Replies in the one-second window that began with the first request counted in it.
  struct Window {
    std::int64_t startNs = 0;
    int replies = 0;
  };
  struct Source {
    std::uint32_t address = 0;  // IPv4, network order
    Window window;
  };

  DiscoveryResponder(hal::UniqueFd socket, std::uint16_t port)
      : socket_(std::move(socket)), port_(port) {}
  // Counts a reply to `address` now; false if a limit is reached.
  bool allowReply(std::uint32_t address, std::int64_t nowNs);

  hal::UniqueFd socket_;
  std::uint16_t port_;
  std::vector<std::byte> answer_;
  std::uint64_t ignored_ = 0;
  std::uint64_t limited_ = 0;
  Window total_;
  std::array<Source, 32> sources_{};  // the most recent; the oldest makes room
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
