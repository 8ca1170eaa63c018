#include "device_socket.hpp"

#include "smx/protocol/messages.hpp"
#include "smx/protocol/secure_keys.hpp"
#include "smx/protocol/secure_messages.hpp"
#include "smx/protocol/stream_parser.hpp"

namespace smx::host {

namespace {

using Fail = std::unexpected<std::string>;
using Clock = std::chrono::steady_clock;
using protocol::MessageType;

// A handshake message or an error's text, with room.
constexpr std::size_t kClearMessageBytes = 4096;

std::chrono::milliseconds leftUntil(Clock::time_point deadline) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
}

std::expected<void, std::string> readExact(net::TcpClient& socket, std::span<std::byte> out,
                                           Clock::time_point deadline) {
  std::size_t have = 0;
  while (have < out.size()) {
    const auto left = leftUntil(deadline);
    if (left.count() <= 0) {
      return Fail("the device did not answer in time");
    }
    const auto got = socket.receiveSome(out.subspan(have), left);
    if (!got) {
      return Fail(got.error());
    }
    have += *got;
  }
  return {};
}

}  // namespace

std::expected<std::pair<MessageType, std::vector<std::byte>>, std::string> readClearMessage(
    net::TcpClient& socket, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  std::vector<std::byte> message(protocol::kHeaderBytes);
  if (auto got = readExact(socket, message, deadline); !got) {
    return Fail(got.error());
  }
  std::size_t length = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    length |= std::to_integer<std::size_t>(message[8 + i]) << (8 * i);
  }
  if (length > kClearMessageBytes) {
    return Fail("the device's answer is not a handshake message");
  }
  message.resize(protocol::kHeaderBytes + length);
  if (auto got = readExact(socket, std::span(message).subspan(protocol::kHeaderBytes), deadline);
      !got) {
    return Fail(got.error());
  }
  protocol::StreamParser parser(kClearMessageBytes);
  (void)parser.feed(message);
  const auto next = parser.next();
  if (!next) {
    return Fail(std::string("a malformed answer: ") + next.error().message);
  }
  const std::optional<protocol::Message>& parsed = *next;
  if (!parsed.has_value()) {
    return Fail("a malformed answer: incomplete");
  }
  const protocol::Message& m = *parsed;
  return std::pair{m.type, std::vector<std::byte>(m.payload.begin(), m.payload.end())};
}

DeviceSocket DeviceSocket::plain(net::TcpClient socket) {
  return {std::move(socket), nullptr};
}

std::expected<DeviceSocket, std::string> DeviceSocket::secure(net::TcpClient socket,
                                                              const protocol::KeyPair& host,
                                                              const protocol::Key32& deviceKey,
                                                              std::chrono::milliseconds timeout) {
  const protocol::KeyPair ephemeral = protocol::generateKeyPair();
  std::array<std::byte, 128> out{};
  const auto hello = protocol::encodeSecureHello(MessageType::kSecureHello,
                                                 {ephemeral.publicKey, host.publicKey}, out);
  if (!hello) {
    return Fail(hello.error().message);
  }
  if (auto sent = socket.sendAll(*hello, timeout); !sent) {
    return Fail(sent.error());
  }
  auto answer = readClearMessage(socket, timeout);
  if (!answer) {
    return Fail(answer.error());
  }
  const auto& [type, payload] = *answer;
  if (type == MessageType::kError) {
    const auto error = protocol::decodeError(payload);
    const std::string text = error ? std::string(error->text) : "unreadable";
    if (error && error->code == protocol::ErrorCode::kNotPaired) {
      return Fail("the device no longer lists this host as paired (" + text +
                  "): run stripemux unpair, then stripemux pair");
    }
    if (error && error->code == protocol::ErrorCode::kBusy) {
      return Fail("the device is busy, " + text);
    }
    return Fail(
        "this host paired with the device, but the device did not open the owner's "
        "channel (" +
        text +
        "); it serves anyone in the clear now (stripemuxd without --state) or is not "
        "the device paired with: refused. stripemux unpair forgets the pairing");
  }
  const auto accept =
      type == MessageType::kSecureAccept
          ? protocol::decodeSecureHello(payload)
          : protocol::protocolFail(protocol::ProtocolErrc::kMalformed, "expected secure-accept");
  if (!accept) {
    return Fail(std::string("bad answer to secure-hello: ") + accept.error().message);
  }
  if (accept->identity != deviceKey) {
    return Fail("the device's key is " + protocol::fingerprint(accept->identity) +
                ", not the paired device's " + protocol::fingerprint(deviceKey) +
                ": another machine answers at this address (or the device's state was reset: "
                "stripemux unpair, then stripemux pair)");
  }
  const auto keys = protocol::deriveSessionKeys(protocol::Role::kHost, ephemeral, host, *accept);
  if (!keys) {
    return Fail("secure-accept: an invalid key");
  }
  auto channel = std::make_unique<protocol::SecureChannel>();
  channel->start(*keys, protocol::Role::kHost);
  if (auto sent = socket.sendAll(channel->pending(), timeout); !sent) {
    return Fail(sent.error());
  }
  channel->sent(channel->pending().size());
  return DeviceSocket(std::move(socket), std::move(channel));
}

std::expected<void, std::string> DeviceSocket::sendAll(std::span<const std::byte> bytes,
                                                       std::chrono::milliseconds timeout) {
  if (!channel_) {
    return socket_.sendAll(bytes, timeout);
  }
  std::size_t done = 0;
  while (done < bytes.size()) {
    done += channel_->seal(bytes.subspan(done));
    if (auto sent = socket_.sendAll(channel_->pending(), timeout); !sent) {
      return sent;
    }
    channel_->sent(channel_->pending().size());
  }
  return {};
}

std::expected<std::size_t, std::string> DeviceSocket::receiveSome(
    std::span<std::byte> bytes, std::chrono::milliseconds timeout) {
  if (!channel_) {
    return socket_.receiveSome(bytes, timeout);
  }
  const auto deadline = Clock::now() + timeout;
  while (true) {
    const auto got = channel_->read(bytes);
    if (!got) {
      return Fail(std::string("the owner's channel failed (") + got.error().message +
                  "): bytes were changed on the way or do not come from the paired device");
    }
    if (*got > 0) {
      return *got;
    }
    const auto space = channel_->writable();
    if (space.empty()) {
      continue;  // a whole unit waits: read() opens it
    }
    const auto left = std::max(leftUntil(deadline), std::chrono::milliseconds(0));
    const auto received = socket_.receiveSome(space, left);
    if (!received) {
      return Fail(received.error());
    }
    if (*received == 0) {
      return 0;
    }
    channel_->commit(*received);
  }
}

}  // namespace smx::host
