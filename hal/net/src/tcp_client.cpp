#include "smx/net/tcp_client.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <system_error>

#include "keepalive.hpp"
#include "poll_fd.hpp"

namespace smx::net {

namespace {

std::int64_t toNs(std::chrono::milliseconds timeout) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
}

}  // namespace

std::expected<DeviceAddress, std::string> parseDeviceAddress(const std::string& text,
                                                             std::uint16_t defaultPort) {
  if (text.empty()) {
    return std::unexpected("the device address is empty (expected HOST or HOST:PORT)");
  }
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) {
    return DeviceAddress{text, defaultPort};
  }
  const std::string host = text.substr(0, colon);
  const std::string portText = text.substr(colon + 1);
  unsigned port = 0;
  const auto [end, ec] = std::from_chars(portText.data(), portText.data() + portText.size(), port);
  if (host.empty() || ec != std::errc{} || end != portText.data() + portText.size() || port == 0 ||
      port > 65535) {
    return std::unexpected("'" + text + "' is not HOST or HOST:PORT with a port in 1..65535");
  }
  return DeviceAddress{host, static_cast<std::uint16_t>(port)};
}

std::expected<TcpClient, std::string> TcpClient::connect(const DeviceAddress& address,
                                                         std::chrono::milliseconds timeout,
                                                         int receiveBufferBytes) {
  const std::string where = address.host + ":" + std::to_string(address.port);
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int err = ::getaddrinfo(address.host.c_str(), nullptr, &hints, &found); err != 0) {
    return std::unexpected("cannot resolve '" + address.host + "': " + ::gai_strerror(err));
  }
  sockaddr_in target{};
  std::memcpy(&target, found->ai_addr, sizeof target);
  ::freeaddrinfo(found);
  target.sin_port = htons(address.port);

  UniqueFd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
  if (!fd.valid()) {
    return std::unexpected(detail::systemError("cannot create a socket"));
  }
  detail::enableKeepAlive(fd.get());  // a device that lost power is noticed while streaming
  if (receiveBufferBytes > 0) {       // before connect: it sets the window the device sees
    ::setsockopt(fd.get(), SOL_SOCKET, SO_RCVBUF, &receiveBufferBytes, sizeof receiveBufferBytes);
  }
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&target), sizeof target) != 0) {
    if (errno != EINPROGRESS) {
      return std::unexpected(detail::systemError("cannot connect to " + where));
    }
    pollfd pending{.fd = fd.get(), .events = POLLOUT, .revents = 0};
    const int ready = detail::pollRetry(&pending, 1, toNs(timeout));
    if (ready == 0) {
      return std::unexpected("cannot connect to " + where + ": no answer within " +
                             std::to_string(timeout.count()) + " ms");
    }
    int err = 0;
    socklen_t length = sizeof err;
    if (ready < 0 || ::getsockopt(fd.get(), SOL_SOCKET, SO_ERROR, &err, &length) != 0) {
      err = errno;
    }
    if (err != 0) {
      return std::unexpected(detail::systemError("cannot connect to " + where, err));
    }
  }
  const int yes = 1;
  ::setsockopt(fd.get(), IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
  return TcpClient(std::move(fd));
}

std::expected<void, std::string> TcpClient::sendAll(std::span<const std::byte> bytes,
                                                    std::chrono::milliseconds timeout) {
  while (!bytes.empty()) {
    const ssize_t sent = ::send(fd_.get(), bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (sent > 0) {
      bytes = bytes.subspan(static_cast<std::size_t>(sent));
      continue;
    }
    if (sent < 0 && !detail::wouldBlock(errno)) {
      return std::unexpected(detail::systemError("sending to the device failed"));
    }
    pollfd fd{.fd = fd_.get(), .events = POLLOUT, .revents = 0};
    if (detail::pollRetry(&fd, 1, toNs(timeout)) == 0) {
      return std::unexpected("the device accepted no data for " + std::to_string(timeout.count()) +
                             " ms");
    }
  }
  return {};
}

std::expected<std::size_t, std::string> TcpClient::receiveSome(std::span<std::byte> bytes,
                                                               std::chrono::milliseconds timeout) {
  pollfd fd{.fd = fd_.get(), .events = POLLIN, .revents = 0};
  const int ready = detail::pollRetry(&fd, 1, toNs(timeout));
  if (ready < 0) {
    return std::unexpected(detail::systemError("waiting for the device failed"));
  }
  if (ready == 0) {
    return 0;
  }
  const ssize_t got = ::recv(fd_.get(), bytes.data(), bytes.size(), 0);
  if (got > 0) {
    return static_cast<std::size_t>(got);
  }
  if (got < 0 && (detail::wouldBlock(errno))) {
    return 0;
  }
  return std::unexpected(got == 0 ? std::string("the device closed the connection")
                                  : detail::systemError("receiving from the device failed"));
}

}  // namespace smx::net
