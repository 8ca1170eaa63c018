#include "smx/net/tcp_link.hpp"

#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstdio>
#include <system_error>

#include "keepalive.hpp"
#include "poll_fd.hpp"
#include "smx/protocol/messages.hpp"
#include "socket_address.hpp"

namespace smx::net {

namespace {

using hal::HalErrc;
using hal::halFail;

// Long enough for a host's request and its close to cross a network, short enough that a host
// that never closes holds only a descriptor for a moment.
constexpr std::int64_t kRefusedLingerNs = 1'000'000'000;

bool setNonBlocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  return flags >= 0 && ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) == 0;
}

bool peerGone(int err) {
  return err == EPIPE || err == ECONNRESET || err == ENOTCONN;
}

// Reads and discards what the peer sent; false once it closed or failed.
bool drain(int fd) {
  std::array<std::byte, 512> sink{};
  while (true) {
    const ssize_t got = ::recv(fd, sink.data(), sink.size(), MSG_DONTWAIT);
    if (got > 0) {
      continue;
    }
    return got < 0 && detail::wouldBlock(errno);
  }
}

}  // namespace

std::expected<std::unique_ptr<TcpLink>, std::string> TcpLink::create(
    const hal::NetworkConfig& network) {
  detail::SocketAddress address;
  if (!detail::numericAddress(network.bindAddress.c_str(), network.port, address)) {
    return std::unexpected("network.bind: '" + network.bindAddress +
                           "' is not an IPv4 or IPv6 address");
  }
  const std::string where =
      (address.family() == AF_INET6 ? "[" + network.bindAddress + "]" : network.bindAddress) + ":" +
      std::to_string(network.port);
  hal::UniqueFd listener(::socket(address.family(), SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!listener.valid()) {
    return std::unexpected(detail::systemError("cannot create a socket"));
  }
  const int yes = 1;
  const int no = 0;
  ::setsockopt(listener.get(), SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  if (address.family() == AF_INET6) {
    // "::" serves IPv4 hosts too, whatever the system's default.
    ::setsockopt(listener.get(), IPPROTO_IPV6, IPV6_V6ONLY, &no, sizeof no);
  }
  if (::bind(listener.get(), address.get(), address.length) != 0) {
    return std::unexpected(detail::systemError("cannot listen on " + where));
  }
  if (::listen(listener.get(), 4) != 0 || !setNonBlocking(listener.get())) {
    return std::unexpected(detail::systemError("cannot listen on " + where));
  }
  detail::SocketAddress bound;
  bound.length = sizeof bound.storage;
  if (::getsockname(listener.get(), bound.get(), &bound.length) != 0) {
    return std::unexpected(detail::systemError("cannot read the port of " + where));
  }
  const auto port = bound.family() == AF_INET6
                        ? reinterpret_cast<const sockaddr_in6*>(&bound.storage)->sin6_port
                        : reinterpret_cast<const sockaddr_in*>(&bound.storage)->sin_port;
  return std::unique_ptr<TcpLink>(
      new TcpLink(std::move(listener), ntohs(port), network.sendBufferBytes));
}

hal::HalResult<void> TcpLink::acceptClient(std::int64_t timeoutNs) {
  if (client_.valid()) {
    return halFail(HalErrc::kInvalidState, "a host is already connected");
  }
  closeRefused(detail::monotonicNs());
  pollfd fd{.fd = listener_.get(), .events = POLLIN, .revents = 0};
  const int ready = detail::pollRetry(&fd, 1, timeoutNs);
  if (ready < 0) {
    return halFail(HalErrc::kIo, "poll on the listening socket failed", errno);
  }
  if (ready == 0) {
    return halFail(HalErrc::kTimeout, "no host connected");
  }
  detail::SocketAddress peer;
  peer.length = sizeof peer.storage;
  hal::UniqueFd client(
      ::accept4(listener_.get(), peer.get(), &peer.length, SOCK_CLOEXEC | SOCK_NONBLOCK));
  if (!client.valid()) {
    if (detail::wouldBlock(errno) || errno == ECONNABORTED) {
      return halFail(HalErrc::kTimeout, "no host connected");
    }
    return halFail(HalErrc::kIo, "accept failed", errno);
  }
  const int yes = 1;
  ::setsockopt(client.get(), IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
  detail::enableKeepAlive(client.get());
  if (sendBufferBytes_ > 0) {
    ::setsockopt(client.get(), SOL_SOCKET, SO_SNDBUF, &sendBufferBytes_, sizeof sendBufferBytes_);
  }
  detail::formatAddress(peer, clientAddress_);
  clientSinceNs_ = detail::monotonicNs();
  client_ = std::move(client);
  return {};
}

void TcpLink::refusePending() {
  const std::int64_t now = detail::monotonicNs();
  while (true) {
    hal::UniqueFd extra(::accept4(listener_.get(), nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK));
    if (!extra.valid()) {
      return;
    }
    ++refused_;
    std::array<char, 128> text{};
    std::snprintf(text.data(), text.size(), "held by %s for %lld s",
                  hideHolder_ ? "another host" : clientAddress_.data(),
                  static_cast<long long>((now - clientSinceNs_) / 1'000'000'000));
    std::array<std::byte, 256> message{};
    const auto busy =
        protocol::encode(protocol::ErrorMessage{protocol::ErrorCode::kBusy, text.data()}, message);
    if (busy) {  // a fresh connection's send buffer is empty: it takes the whole message
      (void)::send(extra.get(), busy->data(), busy->size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    }
    ::shutdown(extra.get(), SHUT_WR);
    Refused* slot = nullptr;
    for (Refused& candidate : refusedOpen_) {
      if (!candidate.fd.valid()) {
        slot = &candidate;
        break;
      }
    }
    if (slot != nullptr) {
      *slot = Refused{std::move(extra), now + kRefusedLingerNs};
    } else {
      (void)drain(extra.get());  // a burst of hosts: this one closes now, what it sent read first
    }
  }
}

void TcpLink::closeRefused(std::int64_t nowNs) {
  for (Refused& slot : refusedOpen_) {
    if (slot.fd.valid() && (!drain(slot.fd.get()) || nowNs >= slot.closeAtNs)) {
      slot.fd.reset();
    }
  }
}

hal::HalResult<std::size_t> TcpLink::sendSome(std::span<const std::byte> bytes) {
  if (!client_.valid()) {
    return halFail(HalErrc::kDisconnected, "no host connected");
  }
  const ssize_t sent = ::send(client_.get(), bytes.data(), bytes.size(), MSG_NOSIGNAL);
  if (sent >= 0) {
    return static_cast<std::size_t>(sent);
  }
  if (detail::wouldBlock(errno)) {
    return 0;
  }
  const int err = errno;
  client_.reset();
  return halFail(peerGone(err) ? HalErrc::kDisconnected : HalErrc::kIo,
                 "sending to the host failed", err);
}

hal::HalResult<std::size_t> TcpLink::receiveSome(std::span<std::byte> bytes,
                                                 std::int64_t timeoutNs) {
  if (!client_.valid()) {
    return halFail(HalErrc::kDisconnected, "no host connected");
  }
  pollfd fd{.fd = client_.get(), .events = POLLIN, .revents = 0};
  const int ready = detail::pollRetry(&fd, 1, timeoutNs);
  if (ready < 0) {
    return halFail(HalErrc::kIo, "poll on the host connection failed", errno);
  }
  if (ready == 0) {
    return 0;
  }
  const ssize_t got = ::recv(client_.get(), bytes.data(), bytes.size(), 0);
  if (got > 0) {
    return static_cast<std::size_t>(got);
  }
  if (got < 0 && (detail::wouldBlock(errno))) {
    return 0;
  }
  const int err = got == 0 ? 0 : errno;
  client_.reset();
  return halFail(HalErrc::kDisconnected, "the host closed the connection", err);
}

hal::HalResult<void> TcpLink::waitForIo(bool wantWrite, std::int64_t timeoutNs) {
  closeRefused(detail::monotonicNs());
  const short clientEvents = wantWrite ? POLLIN | POLLOUT : POLLIN;
  pollfd fds[2] = {{.fd = listener_.get(), .events = POLLIN, .revents = 0},
                   {.fd = client_.get(), .events = clientEvents, .revents = 0}};
  const int ready = detail::pollRetry(fds, client_.valid() ? 2 : 1, timeoutNs);
  if (ready < 0) {
    return halFail(HalErrc::kIo, "poll failed", errno);
  }
  if (client_.valid() && (fds[0].revents & POLLIN) != 0) {
    // A host that reconnects at once may find its old connection not yet noticed as gone.
    pollfd old{.fd = client_.get(), .events = POLLRDHUP, .revents = 0};
    if (detail::pollRetry(&old, 1, 0) > 0 && (old.revents & (POLLRDHUP | POLLHUP | POLLERR)) != 0) {
      client_.reset();  // the new host is accepted by the next acceptClient()
    } else {
      refusePending();
    }
  }
  return {};
}

}  // namespace smx::net
