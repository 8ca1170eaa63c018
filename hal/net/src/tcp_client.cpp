#include "smx/net/tcp_client.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <memory>
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
  const auto bad = [&] {
    return std::unexpected("'" + text +
                           "' is not HOST, HOST:PORT, [IPV6] or [IPV6]:PORT with a port in "
                           "1..65535");
  };
  if (text.empty()) {
    return std::unexpected(
        "the device address is empty (expected HOST, HOST:PORT, [IPV6] or [IPV6]:PORT)");
  }
  std::string host;
  std::string portText;
  bool hasPort = false;
  if (text.front() == '[') {
    const auto close = text.find(']');
    if (close == std::string::npos || close == 1) {
      return bad();
    }
    host = text.substr(1, close - 1);
    const std::string rest = text.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':') {
        return bad();
      }
      portText = rest.substr(1);
      hasPort = true;
    }
  } else if (std::ranges::count(text, ':') == 1) {
    const auto colon = text.find(':');
    host = text.substr(0, colon);
    portText = text.substr(colon + 1);
    hasPort = true;
  } else {
    host = text;  // a name, an IPv4 address or a bare IPv6 address (two colons or more)
  }
  if (host.empty() || host.find_first_of("[]") != std::string::npos) {
    return bad();
  }
  if (!hasPort) {
    return DeviceAddress{host, defaultPort};
  }
  unsigned port = 0;
  const auto [end, ec] = std::from_chars(portText.data(), portText.data() + portText.size(), port);
  if (ec != std::errc{} || end != portText.data() + portText.size() || port == 0 || port > 65535) {
    return bad();
  }
  return DeviceAddress{host, static_cast<std::uint16_t>(port)};
}

std::string toString(const DeviceAddress& address) {
  const bool v6 = address.host.find(':') != std::string::npos;
  return (v6 ? "[" + address.host + "]" : address.host) + ":" + std::to_string(address.port);
}

namespace {

// One attempt on one resolved address; the socket when connected, else the reason.
std::expected<hal::UniqueFd, std::string> connectTo(const addrinfo& target,
                                                    const std::string& where,
                                                    std::chrono::milliseconds timeout,
                                                    int receiveBufferBytes) {
  hal::UniqueFd fd(::socket(target.ai_family, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
  if (!fd.valid()) {
    return std::unexpected(detail::systemError("cannot create a socket"));
  }
  detail::enableKeepAlive(fd.get());  // a device that lost power is noticed while streaming
  if (receiveBufferBytes > 0) {       // before connect: it sets the window the device sees
    ::setsockopt(fd.get(), SOL_SOCKET, SO_RCVBUF, &receiveBufferBytes, sizeof receiveBufferBytes);
  }
  if (::connect(fd.get(), target.ai_addr, target.ai_addrlen) != 0) {
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
  return fd;
}

}  // namespace

std::expected<TcpClient, std::string> TcpClient::connect(const DeviceAddress& address,
                                                         std::chrono::milliseconds timeout,
                                                         int receiveBufferBytes) {
  const std::string where = toString(address);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string port = std::to_string(address.port);
  if (const int err = ::getaddrinfo(address.host.c_str(), port.c_str(), &hints, &found); err != 0) {
    return std::unexpected("cannot resolve '" + address.host + "': " + ::gai_strerror(err));
  }
  const std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> results(found, ::freeaddrinfo);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::string reason = "cannot connect to " + where + ": no address";
  for (const addrinfo* target = found; target != nullptr; target = target->ai_next) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      break;
    }
    auto fd = connectTo(*target, where, left, receiveBufferBytes);
    if (fd) {
      return TcpClient(std::move(*fd));
    }
    reason = fd.error();
  }
  return std::unexpected(reason);
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
