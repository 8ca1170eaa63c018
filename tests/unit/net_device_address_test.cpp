// --device's HOST[:PORT], IPv4, names and IPv6 (parseDeviceAddress, toString).
#include <gtest/gtest.h>

#include <string>

#include "smx/net/tcp_client.hpp"

namespace smx::net {
namespace {

struct Case {
  std::string text;
  std::string host;
  std::uint16_t port;
};

// Given each accepted form, then host and port come out as a socket call wants them (IPv6
// without brackets), and toString() gives back a form --device accepts.
TEST(DeviceAddress, AcceptsHostsPortsAndIpv6WithOrWithoutBrackets) {
  const Case cases[] = {
      {"10.0.0.2", "10.0.0.2", 5555},
      {"10.0.0.2:6000", "10.0.0.2", 6000},
      {"scanner.local:7", "scanner.local", 7},
      {"[::1]:6000", "::1", 6000},
      {"[::1]", "::1", 5555},
      {"::1", "::1", 5555},
      {"fe80::1%eth0", "fe80::1%eth0", 5555},
      {"[fe80::1%eth0]:6000", "fe80::1%eth0", 6000},
      {"2001:db8::17", "2001:db8::17", 5555},
  };
  for (const Case& c : cases) {
    const auto parsed = parseDeviceAddress(c.text, 5555);
    ASSERT_TRUE(parsed.has_value()) << c.text << ": " << parsed.error();
    EXPECT_EQ(parsed->host, c.host) << c.text;
    EXPECT_EQ(parsed->port, c.port) << c.text;
    const auto again = parseDeviceAddress(toString(*parsed), 1);
    ASSERT_TRUE(again.has_value()) << toString(*parsed);
    EXPECT_EQ(again->host, c.host);
    EXPECT_EQ(again->port, c.port);
  }
  EXPECT_EQ(toString({"::1", 6000}), "[::1]:6000");
  EXPECT_EQ(toString({"10.0.0.2", 6000}), "10.0.0.2:6000");
}

// Given malformed addresses, then each is an error naming it.
TEST(DeviceAddress, RejectsMalformedAddresses) {
  for (const std::string bad :
       {"", "10.0.0.2:", "10.0.0.2:0", "10.0.0.2:65536", "10.0.0.2:x", ":5555", "[::1", "[::1]x",
        "[::1]:", "[]:5555", "[::1]:99999", "a[b]:5"}) {
    const auto parsed = parseDeviceAddress(bad, 5555);
    EXPECT_FALSE(parsed.has_value())
        << "'" << bad << "' accepted as " << parsed->host << " port " << parsed->port;
    if (!parsed && !bad.empty()) {
      EXPECT_NE(parsed.error().find(bad), std::string::npos) << parsed.error();
    }
  }
}

}  // namespace
}  // namespace smx::net
