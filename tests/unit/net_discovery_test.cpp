#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "smx/net/discovery.hpp"

namespace smx::net {
namespace {

using namespace std::chrono_literals;

// A responder on a free loopback port, answering on its own thread.
struct RunningResponder {
  explicit RunningResponder(const std::string& board = "bench-board")
      : responder(DiscoveryResponder::create("127.0.0.1", 0, 6123, board).value()), thread([this] {
          while (!stop) {
            (void)responder->serviceOnce(10'000'000);
          }
        }) {}
  ~RunningResponder() { stop = true; }
  RunningResponder(const RunningResponder&) = delete;
  RunningResponder& operator=(const RunningResponder&) = delete;

  std::unique_ptr<DiscoveryResponder> responder;
  std::atomic<bool> stop = false;
  std::jthread thread;
};

TEST(Discovery, AHostFindsTheDeviceWithItsTcpPortAndBoard) {
  const RunningResponder running;
  const auto found = discoverDevices({"127.0.0.1"}, running.responder->port(), 1000ms);
  ASSERT_TRUE(found.has_value()) << found.error();
  ASSERT_EQ(found->size(), 1U);
  EXPECT_EQ((*found)[0].address, "127.0.0.1:6123");
  EXPECT_EQ((*found)[0].board, "bench-board");
}

TEST(Discovery, OtherDatagramsAreIgnoredAndCounted) {
  const RunningResponder running;
  const int sock = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(sock, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(running.responder->port());
  ::inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
  for (const char* junk : {"hello", "SMXP?", "SMXP?\x02", "SMXP!\x01xx"}) {
    ::sendto(sock, junk, std::strlen(junk), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  }
  ::close(sock);
  const auto deadline = std::chrono::steady_clock::now() + 2s;
  while (running.responder->ignored() < 4 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_EQ(running.responder->ignored(), 4U);
  // And a real request still gets its answer.
  const auto found = discoverDevices({"127.0.0.1"}, running.responder->port(), 1000ms);
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->size(), 1U);
}

TEST(Discovery, NobodyAnsweringIsAnEmptyList) {
  const auto found = discoverDevices({"127.0.0.1"}, 9, 100ms);  // discard port: no responder
  ASSERT_TRUE(found.has_value());
  EXPECT_TRUE(found->empty());
  EXPECT_FALSE(discoverDevices({"not-an-address"}, 9, 10ms).has_value());
}

// A UDP socket on `from` (any loopback address: Linux routes all of 127/8 to lo).
class Asker {
 public:
  explicit Asker(const char* from) : fd_(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0)) {
    sockaddr_in self{};
    self.sin_family = AF_INET;
    ::inet_pton(AF_INET, from, &self.sin_addr);
    EXPECT_EQ(::bind(fd_, reinterpret_cast<const sockaddr*>(&self), sizeof self), 0) << from;
  }
  ~Asker() { ::close(fd_); }
  Asker(const Asker&) = delete;
  Asker& operator=(const Asker&) = delete;

  void send(std::uint16_t port, const std::string& datagram) const {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    ::inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
    ::sendto(fd_, datagram.data(), datagram.size(), 0, reinterpret_cast<const sockaddr*>(&to),
             sizeof to);
  }
  // Sizes of the datagrams that arrive until none came for `quietMs`.
  [[nodiscard]] std::vector<std::size_t> answers(int quietMs = 300) const {
    std::vector<std::size_t> sizes;
    std::array<char, 2048> buffer{};
    pollfd p{.fd = fd_, .events = POLLIN, .revents = 0};
    while (::poll(&p, 1, quietMs) > 0) {
      const ssize_t got = ::recv(fd_, buffer.data(), buffer.size(), 0);
      if (got >= 0) {
        sizes.push_back(static_cast<std::size_t>(got));
      }
    }
    return sizes;
  }

 private:
  int fd_;
};

std::string request(std::size_t bytes, char version = 2) {
  std::string r = std::string("SMXP?") + version;
  r.resize(std::max(bytes, r.size()), '\0');
  return r;
}

// Given a device with the longest board name (a 264-byte answer), when requests shorter than
// that answer arrive (the unpadded 6-byte one of version 1, a padded one a byte short), then
// none is answered; a request as long as the answer is answered with no more bytes than it had,
// and the host's own request is such a request.
TEST(Discovery, NoAnswerIsLongerThanItsRequest) {
  const std::string board(255, 'b');
  const RunningResponder running(board);
  const Asker asker("127.0.0.1");
  asker.send(running.responder->port(), request(6, 1));
  asker.send(running.responder->port(), request(kDiscoveryRequestBytes - 1));
  EXPECT_TRUE(asker.answers().empty()) << "a short request was answered";
  EXPECT_EQ(running.responder->ignored(), 2U);

  asker.send(running.responder->port(), request(kDiscoveryRequestBytes));
  const auto answers = asker.answers();
  ASSERT_EQ(answers.size(), 1U);
  EXPECT_EQ(answers[0], kDiscoveryRequestBytes);

  const auto found = discoverDevices({"127.0.0.1"}, running.responder->port(), 1000ms);
  ASSERT_TRUE(found.has_value()) << found.error();
  ASSERT_EQ(found->size(), 1U);
  EXPECT_EQ((*found)[0].board, board);
}

// Given a burst of valid requests, then one source address gets at most
// kDiscoveryRepliesPerSource answers a second and all sources together at most
// kDiscoveryRepliesTotal; the rest are counted.
TEST(Discovery, AnswersAreRateLimitedPerSourceAndInTotal) {
  {
    const RunningResponder running;
    const Asker one("127.0.0.1");
    for (int i = 0; i < 3 * kDiscoveryRepliesPerSource; ++i) {
      one.send(running.responder->port(), request(kDiscoveryRequestBytes));
    }
    const auto answered = one.answers().size();
    EXPECT_GE(answered, 1U);
    EXPECT_LE(answered, std::size_t{kDiscoveryRepliesPerSource}) << "one source";
    EXPECT_GT(running.responder->limited(), 0U);
  }
  const RunningResponder running;
  std::vector<std::unique_ptr<Asker>> many;
  for (int i = 0; i < kDiscoveryRepliesTotal / kDiscoveryRepliesPerSource + 2; ++i) {
    many.push_back(std::make_unique<Asker>(("127.0.0." + std::to_string(i + 2)).c_str()));
    for (int k = 0; k < kDiscoveryRepliesPerSource; ++k) {
      many.back()->send(running.responder->port(), request(kDiscoveryRequestBytes));
    }
  }
  std::this_thread::sleep_for(300ms);
  std::size_t answered = 0;
  for (const auto& asker : many) {
    answered += asker->answers(asker == many.front() ? 300 : 0).size();
  }
  EXPECT_GE(answered, 1U);
  EXPECT_LE(answered, std::size_t{kDiscoveryRepliesTotal}) << "all sources";
}

}  // namespace
}  // namespace smx::net
