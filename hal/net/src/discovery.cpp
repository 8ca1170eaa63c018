#include "smx/net/discovery.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstddef>
#include <cstring>
#include <span>
#include <system_error>

#include "poll_fd.hpp"

namespace smx::net {

namespace {

using Fail = std::unexpected<std::string>;
constexpr std::array<char, 5> kRequestTag = {'S', 'M', 'X', 'P', '?'};
constexpr std::array<char, 5> kAnswerTag = {'S', 'M', 'X', 'P', '!'};
// Version 2: requests padded to the answer's length (version 1's 6-byte request is ignored).
constexpr std::byte kVersion{2};
constexpr std::int64_t kWindowNs = 1'000'000'000;

bool startsWith(std::span<const std::byte> bytes, const std::array<char, 5>& tag) {
  return bytes.size() > tag.size() &&
         std::equal(tag.begin(), tag.end(), bytes.begin(),
                    [](char c, std::byte b) { return static_cast<std::byte>(c) == b; }) &&
         bytes[tag.size()] == kVersion;
}

std::expected<sockaddr_in, std::string> ipv4(const std::string& host, std::uint16_t port) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  if (::inet_pton(AF_INET, host.c_str(), &address.sin_addr) != 1) {
    return Fail("'" + host + "' is not an IPv4 address");
  }
  return address;
}

}  // namespace

std::expected<std::unique_ptr<DiscoveryResponder>, std::string> DiscoveryResponder::create(
    const std::string& bindAddress, std::uint16_t udpPort, std::uint16_t tcpPort,
    const std::string& board) {
  // Discovery is IPv4 (broadcast): a device listening on every IPv6 address ("::") answers on
  // every IPv4 one.
  auto address = ipv4(bindAddress == "::" ? "0.0.0.0" : bindAddress, udpPort);
  if (!address) {
    return Fail("discovery: " + address.error());
  }
  hal::UniqueFd socket(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
  if (!socket.valid()) {
    return Fail(detail::systemError("discovery: cannot create a UDP socket"));
  }
  const int yes = 1;
  ::setsockopt(socket.get(), SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  if (::bind(socket.get(), reinterpret_cast<const sockaddr*>(&*address), sizeof *address) != 0) {
    return Fail(detail::systemError("discovery: cannot listen on UDP " + bindAddress + ":" +
                                    std::to_string(udpPort)));
  }
  sockaddr_in bound{};
  socklen_t length = sizeof bound;
  ::getsockname(socket.get(), reinterpret_cast<sockaddr*>(&bound), &length);
  auto responder = std::unique_ptr<DiscoveryResponder>(
      new DiscoveryResponder(std::move(socket), ntohs(bound.sin_port)));
  const std::size_t nameBytes = std::min<std::size_t>(board.size(), 255);
  auto& answer = responder->answer_;
  for (const char c : kAnswerTag) {
    answer.push_back(static_cast<std::byte>(c));
  }
  answer.push_back(kVersion);
  answer.push_back(static_cast<std::byte>(tcpPort & 0xFFU));
  answer.push_back(static_cast<std::byte>(tcpPort >> 8U));
  answer.push_back(static_cast<std::byte>(nameBytes));
  for (std::size_t i = 0; i < nameBytes; ++i) {
    answer.push_back(static_cast<std::byte>(board[i]));
  }
  return responder;
}

hal::HalResult<int> DiscoveryResponder::serviceOnce(std::int64_t timeoutNs) {
  pollfd fd{.fd = socket_.get(), .events = POLLIN, .revents = 0};
  if (detail::pollRetry(&fd, 1, timeoutNs) <= 0) {
    return 0;
  }
  int answered = 0;
  std::array<std::byte, kDiscoveryRequestBytes + 64> request{};
  while (true) {
    sockaddr_in from{};
    socklen_t fromLength = sizeof from;
    const ssize_t got = ::recvfrom(socket_.get(), request.data(), request.size(), 0,
                                   reinterpret_cast<sockaddr*>(&from), &fromLength);
    if (got < 0) {
      return detail::wouldBlock(errno)
                 ? hal::HalResult<int>(answered)
                 : hal::halFail(hal::HalErrc::kIo, "discovery: recvfrom failed", errno);
    }
    // Never more bytes out than in: a forged source address gains nothing.
    if (static_cast<std::size_t>(got) < answer_.size() ||
        !startsWith(std::span(request).first(static_cast<std::size_t>(got)), kRequestTag)) {
      ++ignored_;
      continue;
    }
    if (!allowReply(from.sin_addr.s_addr, detail::monotonicNs())) {
      ++limited_;
      continue;
    }
    // A lost answer is the host's to retry: UDP.
    (void)::sendto(socket_.get(), answer_.data(), answer_.size(), 0,
                   reinterpret_cast<const sockaddr*>(&from), fromLength);
    ++answered;
  }
}

bool DiscoveryResponder::allowReply(std::uint32_t address, std::int64_t nowNs) {
  const auto take = [nowNs](Window& window, int limit) {
    if (nowNs - window.startNs >= kWindowNs) {
      window = Window{nowNs, 0};
    }
    return window.replies < limit;
  };
  Source* source = &sources_.front();
  for (Source& candidate : sources_) {
    if (candidate.address == address) {
      source = &candidate;
      break;
    }
    if (candidate.window.startNs < source->window.startNs) {
      source = &candidate;
    }
  }
  if (source->address != address) {
    *source = Source{address, Window{nowNs, 0}};
  }
  if (!take(total_, kDiscoveryRepliesTotal) || !take(source->window, kDiscoveryRepliesPerSource)) {
    return false;
  }
  ++total_.replies;
  ++source->window.replies;
  return true;
}

std::expected<std::vector<FoundDevice>, std::string> discoverDevices(
    const std::vector<std::string>& targets, std::uint16_t udpPort,
    std::chrono::milliseconds wait) {
  const hal::UniqueFd socket(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
  if (!socket.valid()) {
    return Fail(detail::systemError("cannot create a UDP socket"));
  }
  const int yes = 1;
  ::setsockopt(socket.get(), SOL_SOCKET, SO_BROADCAST, &yes, sizeof yes);
  std::array<std::byte, kDiscoveryRequestBytes> request{};  // zero padding after the version
  std::transform(kRequestTag.begin(), kRequestTag.end(), request.begin(),
                 [](char c) { return static_cast<std::byte>(c); });
  request[kRequestTag.size()] = kVersion;
  for (const std::string& target : targets) {
    auto address = ipv4(target, udpPort);
    if (!address) {
      return Fail(address.error());
    }
    // An unreachable target (no broadcast route in a container) is not an error here.
    (void)::sendto(socket.get(), request.data(), request.size(), 0,
                   reinterpret_cast<const sockaddr*>(&*address), sizeof *address);
  }
  std::vector<FoundDevice> found;
  const auto deadline = std::chrono::steady_clock::now() + wait;
  while (true) {
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(
        deadline - std::chrono::steady_clock::now());
    pollfd fd{.fd = socket.get(), .events = POLLIN, .revents = 0};
    if (left.count() <= 0 || detail::pollRetry(&fd, 1, left.count()) <= 0) {
      return found;
    }
    std::array<std::byte, 512> answer{};
    sockaddr_in from{};
    socklen_t fromLength = sizeof from;
    const ssize_t got = ::recvfrom(socket.get(), answer.data(), answer.size(), 0,
                                   reinterpret_cast<sockaddr*>(&from), &fromLength);
    const std::size_t header = kAnswerTag.size() + 4;
    if (got < static_cast<ssize_t>(header) ||
        !startsWith(std::span(answer).first(static_cast<std::size_t>(got)), kAnswerTag)) {
      continue;
    }
    const auto tcpPort = static_cast<std::uint16_t>(std::to_integer<unsigned>(answer[6]) |
                                                    std::to_integer<unsigned>(answer[7]) << 8U);
    const auto nameBytes = std::to_integer<std::size_t>(answer[8]);
    if (static_cast<std::size_t>(got) != header + nameBytes) {
      continue;
    }
    std::array<char, INET_ADDRSTRLEN> text{};
    ::inet_ntop(AF_INET, &from.sin_addr, text.data(), text.size());
    FoundDevice device{
        std::string(text.data()) + ":" + std::to_string(tcpPort),
        std::string(reinterpret_cast<const char*>(answer.data() + header), nameBytes)};
    if (std::ranges::none_of(found,
                             [&](const FoundDevice& d) { return d.address == device.address; })) {
      found.push_back(std::move(device));
    }
  }
}

}  // namespace smx::net
