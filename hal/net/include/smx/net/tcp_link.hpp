#pragma once

#include <expected>
#include <memory>
#include <string>

#include "smx/hal/board_config.hpp"
#include "smx/hal/link.hpp"
#include "smx/net/unique_fd.hpp"

// hal::Link over TCP (IPv4): listens on the board's address and port and serves one host; a
// second host that connects while one is served is accepted and closed at once, so it sees the
// device as busy instead of hanging in the backlog. Used by every board, the simulated one too.
namespace smx::net {

class TcpLink final : public hal::Link {
 public:
  // Binds and listens (init time). The error names the address and the system's reason.
  [[nodiscard]] static std::expected<std::unique_ptr<TcpLink>, std::string> create(
      const hal::NetworkConfig& network);

  [[nodiscard]] hal::HalResult<void> acceptClient(std::int64_t timeoutNs) override;
  [[nodiscard]] bool connected() const override { return client_.valid(); }
  [[nodiscard]] hal::HalResult<std::size_t> sendSome(std::span<const std::byte> bytes) override;
  [[nodiscard]] hal::HalResult<std::size_t> receiveSome(std::span<std::byte> bytes,
                                                        std::int64_t timeoutNs) override;
  [[nodiscard]] hal::HalResult<void> waitForIo(bool wantWrite, std::int64_t timeoutNs) override;
  void disconnect() override { client_.reset(); }
  [[nodiscard]] std::uint16_t port() const override { return port_; }

  // Hosts turned away because one was already connected.
  [[nodiscard]] std::uint64_t refusedClients() const { return refused_; }

 private:
  TcpLink(UniqueFd listener, std::uint16_t port, int sendBufferBytes)
      : listener_(std::move(listener)), port_(port), sendBufferBytes_(sendBufferBytes) {}
  void refusePending();

  UniqueFd listener_;
  UniqueFd client_;
  std::uint16_t port_;
  int sendBufferBytes_;
  std::uint64_t refused_ = 0;
};

}  // namespace smx::net
