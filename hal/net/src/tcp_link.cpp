#include "smx/net/tcp_link.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include "poll_fd.hpp"

namespace smx::net {

namespace {

using hal::HalErrc;
using hal::halFail;

bool setNonBlocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  return flags >= 0 && ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) == 0;
}

bool peerGone(int err) {
  return err == EPIPE || err == ECONNRESET || err == ENOTCONN;
}

}  // namespace

std::expected<std::unique_ptr<TcpLink>, std::string> TcpLink::create(
    const hal::NetworkConfig& network) {
  const std::string where = network.bindAddress + ":" + std::to_string(network.port);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(network.port);
  if (::inet_pton(AF_INET, network.bindAddress.c_str(), &address.sin_addr) != 1) {
    return std::unexpected("network.bind: '" + network.bindAddress + "' is not an IPv4 address");
  }
  UniqueFd listener(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!listener.valid()) {
    return std::unexpected(detail::systemError("cannot create a socket"));
  }
  const int yes = 1;
  ::setsockopt(listener.get(), SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  if (::bind(listener.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    return std::unexpected(detail::systemError("cannot listen on " + where));
  }
  if (::listen(listener.get(), 4) != 0 || !setNonBlocking(listener.get())) {
    return std::unexpected(detail::systemError("cannot listen on " + where));
  }
  sockaddr_in bound{};
  socklen_t length = sizeof bound;
  if (::getsockname(listener.get(), reinterpret_cast<sockaddr*>(&bound), &length) != 0) {
    return std::unexpected(detail::systemError("cannot read the port of " + where));
  }
  return std::unique_ptr<TcpLink>(
      new TcpLink(std::move(listener), ntohs(bound.sin_port), network.sendBufferBytes));
}

hal::HalResult<void> TcpLink::acceptClient(std::int64_t timeoutNs) {
  if (client_.valid()) {
    return halFail(HalErrc::kInvalidState, "a host is already connected");
  }
  pollfd fd{.fd = listener_.get(), .events = POLLIN, .revents = 0};
  const int ready = detail::pollRetry(&fd, 1, timeoutNs);
  if (ready < 0) {
    return halFail(HalErrc::kIo, "poll on the listening socket failed", errno);
  }
  if (ready == 0) {
    return halFail(HalErrc::kTimeout, "no host connected");
  }
  UniqueFd client(::accept4(listener_.get(), nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK));
  if (!client.valid()) {
    if (detail::wouldBlock(errno) || errno == ECONNABORTED) {
      return halFail(HalErrc::kTimeout, "no host connected");
    }
    return halFail(HalErrc::kIo, "accept failed", errno);
  }
  const int yes = 1;
  ::setsockopt(client.get(), IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
  if (sendBufferBytes_ > 0) {
    ::setsockopt(client.get(), SOL_SOCKET, SO_SNDBUF, &sendBufferBytes_, sizeof sendBufferBytes_);
  }
  client_ = std::move(client);
  return {};
}

void TcpLink::refusePending() {
  while (true) {
    const UniqueFd extra(
        ::accept4(listener_.get(), nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK));
    if (!extra.valid()) {
      return;
    }
    ++refused_;
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
