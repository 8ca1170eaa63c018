#pragma once

#include <array>
#include <cstdint>
#include <expected>
#include <memory>
#include <string>

#include "smx/hal/board_config.hpp"
#include "smx/hal/link.hpp"
#include "smx/hal/unique_fd.hpp"

// hal::Link over TCP, IPv4 or IPv6 (docs/protocol.md "Connections"): listens on the board's
// address and port and serves one host, with TCP keepalive. A second host that connects while
// one is served gets the protocol's `busy` error naming the host that holds the device and for
// how long, then the connection is closed: it learns why at once instead of hanging in the
// backlog. Used by every board, the simulated one too. No heap after create().
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
  // The busy error then says "another host" instead of its address: an owned device tells an
  // unauthenticated peer nothing about who uses it (docs/security.md).
  void hideHolder() { hideHolder_ = true; }

 private:
  // A turned-away host's connection: its `busy` error is sent and our side shut down; it is
  // closed when the host closes or after kRefusedLingerNs, so that a request the host sent
  // meanwhile does not make the kernel reset the connection before the host read the error.
  struct Refused {
    hal::UniqueFd fd;
    std::int64_t closeAtNs = 0;
  };

  TcpLink(hal::UniqueFd listener, std::uint16_t port, int sendBufferBytes)
      : listener_(std::move(listener)), port_(port), sendBufferBytes_(sendBufferBytes) {}
  void refusePending();
  void closeRefused(std::int64_t nowNs);

  hal::UniqueFd listener_;
  hal::UniqueFd client_;
  std::uint16_t port_;
  int sendBufferBytes_;
  std::uint64_t refused_ = 0;
  bool hideHolder_ = false;
  std::array<char, 64> clientAddress_{};  // "a.b.c.d:port" or "[v6]:port"
  std::int64_t clientSinceNs_ = 0;        // CLOCK_MONOTONIC
  std::array<Refused, 4> refusedOpen_;
};

}  // namespace smx::net
