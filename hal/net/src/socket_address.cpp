#include "socket_address.hpp"

#include <arpa/inet.h>
#include <net/if.h>

#include <cstdio>
#include <cstring>

namespace smx::net::detail {

bool numericAddress(const char* host, std::uint16_t port, SocketAddress& out) {
  out = SocketAddress{};
  auto* v4 = reinterpret_cast<sockaddr_in*>(&out.storage);
  if (::inet_pton(AF_INET, host, &v4->sin_addr) == 1) {
    v4->sin_family = AF_INET;
    v4->sin_port = htons(port);
    out.length = sizeof(sockaddr_in);
    return true;
  }
  // A link-local address needs its interface: "fe80::1%eth0".
  std::array<char, INET6_ADDRSTRLEN + IF_NAMESIZE + 1> text{};
  const char* percent = std::strchr(host, '%');
  const std::size_t addressChars =
      percent == nullptr ? std::strlen(host) : static_cast<std::size_t>(percent - host);
  if (addressChars >= INET6_ADDRSTRLEN) {
    return false;
  }
  std::memcpy(text.data(), host, addressChars);
  auto* v6 = reinterpret_cast<sockaddr_in6*>(&out.storage);
  if (::inet_pton(AF_INET6, text.data(), &v6->sin6_addr) != 1) {
    return false;
  }
  if (percent != nullptr) {
    v6->sin6_scope_id = ::if_nametoindex(percent + 1);
    if (v6->sin6_scope_id == 0) {
      return false;
    }
  }
  v6->sin6_family = AF_INET6;
  v6->sin6_port = htons(port);
  out.length = sizeof(sockaddr_in6);
  return true;
}

void formatAddress(const SocketAddress& address, AddressText& out) {
  std::array<char, INET6_ADDRSTRLEN> host{};
  if (address.family() == AF_INET) {
    const auto* v4 = reinterpret_cast<const sockaddr_in*>(&address.storage);
    ::inet_ntop(AF_INET, &v4->sin_addr, host.data(), host.size());
    std::snprintf(out.data(), out.size(), "%s:%u", host.data(), unsigned{ntohs(v4->sin_port)});
  } else if (address.family() == AF_INET6) {
    const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&address.storage);
    const unsigned port = ntohs(v6->sin6_port);
    if (IN6_IS_ADDR_V4MAPPED(&v6->sin6_addr)) {
      ::inet_ntop(AF_INET, &v6->sin6_addr.s6_addr[12], host.data(), host.size());
      std::snprintf(out.data(), out.size(), "%s:%u", host.data(), port);
    } else {
      ::inet_ntop(AF_INET6, &v6->sin6_addr, host.data(), host.size());
      std::snprintf(out.data(), out.size(), "[%s]:%u", host.data(), port);
    }
  } else {
    std::snprintf(out.data(), out.size(), "?");
  }
}

}  // namespace smx::net::detail
