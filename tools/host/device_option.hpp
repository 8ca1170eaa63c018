#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdint>
#include <string>

#include "smx/net/tcp_client.hpp"
#include "smx/protocol/wire.hpp"

// The --device HOST[:PORT] option of the commands that talk to a device.
namespace smx::host {

inline constexpr auto kDeviceConnectTimeout = std::chrono::milliseconds(3000);

// A --timeout or --wait option's seconds as a duration (whole milliseconds, truncated).
inline std::chrono::milliseconds secondsOption(double seconds) {
  return std::chrono::milliseconds(static_cast<std::int64_t>(seconds * 1000));
}

// A device on this machine shares the host's CLOCK_MONOTONIC, so capture → host latency can be
// read from its timestamps.
inline bool isLoopback(const std::string& address) {
  return address.starts_with("127.") || address.starts_with("localhost") ||
         address.starts_with("[::1]");
}

// A malformed HOST[:PORT] is a usage error (exit 1), found before any connection is tried.
inline CLI::Validator deviceAddressValidator() {
  return {[](const std::string& text) {
            const auto parsed = net::parseDeviceAddress(text, protocol::kDefaultPort);
            return parsed ? std::string() : parsed.error();
          },
          "HOST[:PORT]"};
}

}  // namespace smx::host
