#pragma once

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

// TCP keepalive on a connection, both ends (docs/protocol.md "Connections"): a peer that vanished
// without a word (power cut, cable pulled, a laptop gone to sleep) is noticed after about
// 10 s of silence + 3 probes 5 s apart = 25 s, instead of the kernel's default two hours.
namespace smx::net::detail {

inline constexpr int kKeepAliveIdleS = 10;
inline constexpr int kKeepAliveIntervalS = 5;
inline constexpr int kKeepAliveProbes = 3;

// Best effort: a socket without keepalive still works, the idle timeout still applies.
inline void enableKeepAlive(int fd) {
  const int yes = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_KEEPALIVE, &yes, sizeof yes);
  ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &kKeepAliveIdleS, sizeof kKeepAliveIdleS);
  ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &kKeepAliveIntervalS, sizeof kKeepAliveIntervalS);
  ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &kKeepAliveProbes, sizeof kKeepAliveProbes);
}

}  // namespace smx::net::detail
