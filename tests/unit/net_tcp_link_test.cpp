// The device end of the link (TcpLink) and the host end (TcpClient) on loopback: one host is
// served, a second is told who holds the device, both ends probe with TCP keepalive.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "smx/net/tcp_client.hpp"
#include "smx/net/tcp_link.hpp"
#include "smx/protocol/messages.hpp"
#include "smx/protocol/stream_parser.hpp"

namespace smx::net {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

std::unique_ptr<TcpLink> loopbackLink() {
  hal::NetworkConfig network;
  network.bindAddress = "127.0.0.1";
  network.port = 0;
  auto link = TcpLink::create(network);
  EXPECT_TRUE(link.has_value()) << link.error();
  return std::move(*link);
}

// A plain blocking socket connected to 127.0.0.1:port; its own port in `localPort`.
hal::UniqueFd connectRaw(std::uint16_t port, std::uint16_t& localPort) {
  hal::UniqueFd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(port);
  ::inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
  EXPECT_EQ(::connect(fd.get(), reinterpret_cast<const sockaddr*>(&to), sizeof to), 0);
  sockaddr_in self{};
  socklen_t length = sizeof self;
  ::getsockname(fd.get(), reinterpret_cast<sockaddr*>(&self), &length);
  localPort = ntohs(self.sin_port);
  return fd;
}

// Reads until one whole message arrived, the peer closed, or 5 s passed.
std::optional<std::pair<protocol::MessageType, std::vector<std::byte>>> readMessage(int fd) {
  protocol::StreamParser parser(4096);
  const auto deadline = Clock::now() + 5s;
  while (Clock::now() < deadline) {
    if (auto next = parser.next(); next && next->has_value()) {
      const protocol::Message& m = **next;
      return std::pair{m.type, std::vector<std::byte>(m.payload.begin(), m.payload.end())};
    }
    pollfd p{.fd = fd, .events = POLLIN, .revents = 0};
    if (::poll(&p, 1, 100) <= 0) {
      continue;
    }
    const auto writable = parser.writable();
    const ssize_t got = ::recv(fd, writable.data(), writable.size(), 0);
    if (got <= 0) {
      return std::nullopt;
    }
    parser.commit(static_cast<std::size_t>(got));
  }
  return std::nullopt;
}

// Given a host served by the link, when a second host connects, then the second gets a `busy`
// error naming the first (address:port, and since when) and is closed, while the first keeps
// its connection both ways.
TEST(TcpLink, ASecondHostIsToldBusyWithTheHolderAndTheFirstIsUnaffected) {
  const auto link = loopbackLink();
  std::uint16_t firstPort = 0;
  const hal::UniqueFd first = connectRaw(link->port(), firstPort);
  ASSERT_TRUE(link->acceptClient(2'000'000'000).has_value());

  std::uint16_t secondPort = 0;
  const hal::UniqueFd second = connectRaw(link->port(), secondPort);
  const auto deadline = Clock::now() + 5s;
  while (link->refusedClients() == 0 && Clock::now() < deadline) {
    ASSERT_TRUE(link->waitForIo(false, 10'000'000).has_value());
  }
  ASSERT_EQ(link->refusedClients(), 1U);

  const auto reply = readMessage(second.get());
  ASSERT_TRUE(reply.has_value()) << "the second host got no message before the device closed";
  ASSERT_EQ(reply->first, protocol::MessageType::kError);
  const auto error = protocol::decodeError(reply->second);
  ASSERT_TRUE(error.has_value());
  EXPECT_EQ(error->code, protocol::ErrorCode::kBusy);
  const std::string text(error->text);
  const std::string holder = "held by 127.0.0.1:" + std::to_string(firstPort) + " for ";
  EXPECT_NE(text.find(holder), std::string::npos) << text;
  EXPECT_TRUE(text.ends_with(" s")) << text;
  std::array<char, 16> rest{};
  EXPECT_EQ(::recv(second.get(), rest.data(), rest.size(), 0), 0) << "not closed after busy";

  EXPECT_TRUE(link->connected());
  const std::array<std::byte, 4> ping{std::byte{'p'}, std::byte{'i'}, std::byte{'n'},
                                      std::byte{'g'}};
  ASSERT_EQ(link->sendSome(ping).value_or(0), ping.size());
  std::array<std::byte, 4> got{};
  ASSERT_EQ(::recv(first.get(), got.data(), got.size(), MSG_WAITALL), 4);
  EXPECT_EQ(got, ping);
  ASSERT_EQ(::send(first.get(), got.data(), got.size(), 0), 4);
  std::array<std::byte, 4> back{};
  EXPECT_EQ(link->receiveSome(back, 2'000'000'000).value_or(0), 4U);
}

// The timer kind of each established loopback connection with `port` on one side, from
// /proc/net/tcp ("tr": 2 = keepalive armed): the device's end (local port) and the host's
// (remote port).
struct Timers {
  int deviceEnd = -1;
  int hostEnd = -1;
};
Timers keepaliveTimers(std::uint16_t port) {
  std::ifstream table("/proc/net/tcp");
  std::string line;
  std::getline(table, line);  // header
  Timers timers;
  while (std::getline(table, line)) {
    std::istringstream fields(line);
    std::string slot, local, remote, state, queues, timer;
    fields >> slot >> local >> remote >> state >> queues >> timer;
    if (state != "01") {  // established
      continue;
    }
    const auto portOf = [](const std::string& a) {
      return static_cast<std::uint16_t>(std::stoul(a.substr(a.find(':') + 1), nullptr, 16));
    };
    const int kind = std::stoi(timer.substr(0, timer.find(':')), nullptr, 16);
    if (portOf(local) == port) {
      timers.deviceEnd = kind;
    } else if (portOf(remote) == port) {
      timers.hostEnd = kind;
    }
  }
  return timers;
}

// Given a host connected with TcpClient to a TcpLink, then both ends have keepalive armed, so a
// vanished peer is noticed without traffic.
TEST(TcpLink, BothEndsOfAConnectionProbeWithKeepalive) {
  const auto link = loopbackLink();
  auto client = TcpClient::connect({"127.0.0.1", link->port()}, 2000ms);
  ASSERT_TRUE(client.has_value()) << client.error();
  ASSERT_TRUE(link->acceptClient(2'000'000'000).has_value());
  const Timers timers = keepaliveTimers(link->port());
  EXPECT_EQ(timers.deviceEnd, 2) << "the device's end of the connection has no keepalive";
  EXPECT_EQ(timers.hostEnd, 2) << "the host's end of the connection has no keepalive";
}

// Given a link listening on every address ("::"), when a host connects over IPv6 loopback with
// TcpClient, then it is served, and an IPv4 host that comes second is told the IPv6 holder.
TEST(TcpLink, ServesIpv6HostsAndIpv4OnesOnEveryAddress) {
  hal::NetworkConfig network;
  network.bindAddress = "::";
  network.port = 0;
  auto link = TcpLink::create(network);
  ASSERT_TRUE(link.has_value()) << link.error();
  auto client = TcpClient::connect({"::1", (*link)->port()}, 2000ms);
  if (!client && client.error().find("Cannot assign") != std::string::npos) {
    GTEST_SKIP() << "no IPv6 loopback: " << client.error();
  }
  ASSERT_TRUE(client.has_value()) << client.error();
  ASSERT_TRUE((*link)->acceptClient(2'000'000'000).has_value());

  std::uint16_t secondPort = 0;
  const hal::UniqueFd second = connectRaw((*link)->port(), secondPort);
  const auto deadline = Clock::now() + 5s;
  while ((*link)->refusedClients() == 0 && Clock::now() < deadline) {
    ASSERT_TRUE((*link)->waitForIo(false, 10'000'000).has_value());
  }
  const auto reply = readMessage(second.get());
  ASSERT_TRUE(reply.has_value());
  const auto error = protocol::decodeError(reply->second);
  ASSERT_TRUE(error.has_value());
  EXPECT_NE(std::string(error->text).find("held by [::1]:"), std::string::npos) << error->text;
}

}  // namespace
}  // namespace smx::net
