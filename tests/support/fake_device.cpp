#include "fake_device.hpp"

#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

#include "smx/protocol/messages.hpp"
#include "smx/protocol/stream_parser.hpp"

namespace smx::test {
namespace {

bool sendAll(int fd, std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n <= 0) {
      return false;
    }
    bytes = bytes.subspan(static_cast<std::size_t>(n));
  }
  return true;
}

}  // namespace

FakeDevice::FakeDevice(FakeDeviceScript script) : script_(std::move(script)) {
  listener_.reset(::socket(AF_INET, SOCK_STREAM, 0));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof addr;
  if (!listener_.valid() || ::bind(listener_.get(), reinterpret_cast<sockaddr*>(&addr), len) != 0 ||
      ::listen(listener_.get(), 1) != 0 ||
      ::getsockname(listener_.get(), reinterpret_cast<sockaddr*>(&addr), &len) != 0) {
    throw std::runtime_error("fake device: cannot listen on 127.0.0.1");
  }
  port_ = ntohs(addr.sin_port);
  thread_ = std::thread([this] { serve(); });
}

FakeDevice::~FakeDevice() {
  stop_ = true;
  thread_.join();
}

std::string FakeDevice::address() const {
  return "127.0.0.1:" + std::to_string(port_);
}

void FakeDevice::serve() {
  pollfd waiting{listener_.get(), POLLIN, 0};
  while (!stop_ && ::poll(&waiting, 1, 50) == 0) {
  }
  if (stop_) {
    return;
  }
  const hal::UniqueFd client(::accept(listener_.get(), nullptr, nullptr));
  if (!client.valid()) {
    return;
  }
  protocol::StreamParser parser(protocol::kMaxPayloadBytes);
  std::vector<std::byte> out(protocol::rangeFrameBound(script_.width, script_.height) + 65536);
  const std::vector<std::uint16_t> depth(
      static_cast<std::size_t>(script_.width) * static_cast<std::size_t>(script_.height), 1000);
  std::uint64_t frame = 0;
  while (!stop_) {
    pollfd readable{client.get(), POLLIN, 0};
    if (::poll(&readable, 1, 50) <= 0) {
      continue;
    }
    const auto space = parser.writable();
    const ssize_t n = ::recv(client.get(), space.data(), space.size(), 0);
    if (n <= 0) {
      return;
    }
    parser.commit(static_cast<std::size_t>(n));
    while (true) {
      const auto next = parser.next();
      if (!next) {
        continue;  // skipped by the parser
      }
      const std::optional<protocol::Message>& parsed = *next;
      if (!parsed.has_value()) {
        break;
      }
      const protocol::Message& message = *parsed;
      std::optional<protocol::ProtocolResult<std::span<const std::byte>>> reply;
      switch (message.type) {
        case protocol::MessageType::kHello: {
          protocol::Capabilities caps;
          caps.board = script_.board;
          caps.firmwareVersion = script_.firmwareVersion;
          caps.halBackend = "sim";
          caps.cameras = 1;
          caps.projectors = 2;
          caps.width = static_cast<std::uint16_t>(script_.width);
          caps.height = static_cast<std::uint16_t>(script_.height);
          caps.fps = 30;
          caps.compressionsMask = 3;
          caps.rigJson = script_.rigJson;
          reply = protocol::encode(caps, out);
          break;
        }
        case protocol::MessageType::kStartStream:
          for (int i = 0; i < script_.framesPerStart; ++i) {
            protocol::RangeFrameHeader header;
            header.width = static_cast<std::uint16_t>(script_.width);
            header.height = static_cast<std::uint16_t>(script_.height);
            header.frame = frame++;
            const auto encoded = protocol::encodeRangeFrame(
                header, *algo::ConstDepthPlane::packed(depth, script_.width, script_.height), out);
            if (!encoded || !sendAll(client.get(), *encoded)) {
              return;
            }
          }
          break;
        case protocol::MessageType::kStopStream:
        case protocol::MessageType::kGetStatistics:
          reply = protocol::encode(protocol::Statistics{}, out);
          break;
        default:
          break;
      }
      if (reply && (!*reply || !sendAll(client.get(), **reply))) {
        return;
      }
    }
  }
}

}  // namespace smx::test
