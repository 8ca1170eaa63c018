#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <thread>

#include "smx/net/discovery.hpp"

namespace smx::net {
namespace {

using namespace std::chrono_literals;

// A responder on a free loopback port, answering on its own thread.
struct RunningResponder {
  RunningResponder()
      : responder(DiscoveryResponder::create("127.0.0.1", 0, 6123, "bench-board").value()),
        thread([this] {
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

}  // namespace
}  // namespace smx::net
