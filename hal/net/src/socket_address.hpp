#pragma once

#include <netinet/in.h>
#include <sys/socket.h>

#include <array>
#include <cstdint>
#include <string_view>

// Numeric socket addresses, IPv4 or IPv6, parsed and printed without the heap: the device's
// network loop names the host it serves while it turns another away.
namespace smx::net::detail {

struct SocketAddress {
  sockaddr_storage storage{};
  socklen_t length = 0;

  [[nodiscard]] const sockaddr* get() const { return reinterpret_cast<const sockaddr*>(&storage); }
  [[nodiscard]] sockaddr* get() { return reinterpret_cast<sockaddr*>(&storage); }
  [[nodiscard]] int family() const { return storage.ss_family; }
};

// "a.b.c.d" or an IPv6 literal without brackets ("::1", "fe80::1%eth0"); false if neither.
[[nodiscard]] bool numericAddress(const char* host, std::uint16_t port, SocketAddress& out);

// "[" INET6_ADDRSTRLEN "]:65535" and a NUL.
using AddressText = std::array<char, 64>;

// "a.b.c.d:port" or "[v6]:port"; an IPv4-mapped IPv6 address (a v4 host on a dual-stack socket)
// prints as IPv4. "?" for another family.
void formatAddress(const SocketAddress& address, AddressText& out);
[[nodiscard]] inline std::string_view view(const AddressText& text) {
  return text.data();
}

}  // namespace smx::net::detail
