#include "device_client.hpp"

#include <algorithm>
#include <optional>
#include <string>

#include "pairing_store.hpp"
#include "smx/config/identifier.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/hal/steady_clock.hpp"

namespace smx::host {

namespace {

using Fail = std::unexpected<std::string>;
using protocol::MessageType;

// About five range frames: enough to ride out a slow file write, small enough that a host that
// keeps falling behind sees fresh frames (the device drops the oldest) rather than old ones.
constexpr int kReceiveBufferBytes = 1 << 20;
// How long a host whose hello could not be sent looks for the device's reason (`busy`).
constexpr auto kRefusalWait = std::chrono::milliseconds(500);

std::string deviceError(std::span<const std::byte> payload) {
  const auto error = protocol::decodeError(payload);
  if (!error) {
    return "the device reported an error (unreadable)";
  }
  if (error->code == protocol::ErrorCode::kBusy) {
    return "the device is busy, " + std::string(error->text) +
           "; it serves one host at a time: try again when that host is done";
  }
  return "the device refused: " + std::string(error->text);
}

// The capabilities announce counts and a size that the range frames are checked against; they
// must be the rig's, or a device could announce one thing and describe another.
std::optional<std::string> announcementMismatch(const DeviceInfo& info) {
  const auto& rig = info.rig;
  if (static_cast<std::size_t>(info.cameras) != rig.cameras.size() ||
      static_cast<std::size_t>(info.projectors) != rig.projectors.size()) {
    return "the device announced " + std::to_string(info.cameras) + " cameras and " +
           std::to_string(info.projectors) + " projectors, but its rig has " +
           std::to_string(rig.cameras.size()) + " and " + std::to_string(rig.projectors.size());
  }
  for (const auto& camera : rig.cameras) {
    if (camera.width != info.width || camera.height != info.height) {
      return "the device announced " + std::to_string(info.width) + "x" +
             std::to_string(info.height) + " images, but its rig's " + camera.id + " is " +
             std::to_string(camera.width) + "x" + std::to_string(camera.height);
    }
  }
  return std::nullopt;
}

}  // namespace

DeviceClient::DeviceClient(DeviceSocket socket, std::string address)
    : socket_(std::move(socket)),
      parser_(std::make_unique<protocol::StreamParser>(protocol::kMaxPayloadBytes)),
      out_(4096) {
  info_.address = std::move(address);
}

std::expected<DeviceClient, std::string> DeviceClient::connect(const std::string& address,
                                                               std::chrono::milliseconds timeout) {
  const auto parsed = net::parseDeviceAddress(address, protocol::kDefaultPort);
  if (!parsed) {
    return Fail("--device: " + parsed.error());
  }
  const std::string where = net::toString(*parsed);
  // A device this host paired with is spoken to over the owner's channel only, never in the
  // clear (docs/security.md "Choosing the channel").
  const auto pairedKey = pairedDeviceKey(*parsed);
  if (!pairedKey) {
    return Fail(pairedKey.error());
  }
  auto socket = net::TcpClient::connect(*parsed, timeout, kReceiveBufferBytes);
  if (!socket) {
    return Fail(socket.error());
  }
  auto stream = [&]() -> std::expected<DeviceSocket, std::string> {
    if (!pairedKey->has_value()) {
      return DeviceSocket::plain(std::move(*socket));
    }
    auto identity = hostIdentity();
    if (!identity) {
      return Fail(identity.error());
    }
    return DeviceSocket::secure(std::move(*socket), *identity, **pairedKey, timeout);
  }();
  if (!stream) {
    return Fail(where + ": " + stream.error());
  }
  DeviceClient client(std::move(*stream), where);
  const auto hello =
      client.send(protocol::encode(protocol::Hello{"stripemux " SMX_VERSION}, client.out_));
  // A busy device closes at once; its error may be waiting even when the hello failed.
  auto reply = client.nextMessage(hello ? timeout : std::min(timeout, kRefusalWait));
  bool refused = false;
  if (reply) {
    const auto& answer = *reply;
    refused = answer.has_value() && answer->first == MessageType::kError;
  }
  if (!hello && !refused) {
    return Fail(where + ": " + hello.error());
  }
  if (!reply) {
    return Fail(where + ": " + reply.error());
  }
  const auto& answer = *reply;
  if (!answer.has_value()) {
    return Fail(where + ": the device did not answer hello within " +
                std::to_string(timeout.count()) + " ms (is it a stripemux device?)");
  }
  const auto& [type, payload] = *answer;
  if (type == MessageType::kError) {
    const auto error = protocol::decodeError(payload);
    if (error && error->code == protocol::ErrorCode::kNotPaired) {
      return Fail(where +
                  ": this host is not paired with the device, which serves its owner's "
                  "hosts only: run stripemux pair --device " +
                  where);
    }
    return Fail(where + ": " + deviceError(payload));
  }
  const auto caps =
      type == MessageType::kCapabilities
          ? protocol::decodeCapabilities(payload)
          : protocol::protocolFail(protocol::ProtocolErrc::kMalformed, "expected capabilities");
  if (!caps) {
    return Fail(where + ": bad answer to hello: " + caps.error().message);
  }
  DeviceInfo& info = client.info_;
  // The board name is an id like any other (docs/rig-format.md, "Ids"): devices are not trusted.
  if (auto problem = config::identifierProblem(caps->board)) {
    return Fail(where + ": the device's board name " + *problem);
  }
  info.board = caps->board;
  info.firmwareVersion = caps->firmwareVersion;
  info.halBackend = caps->halBackend;
  info.depthUnitM = caps->depthUnitNm * 1e-9;
  info.cameras = caps->cameras;
  info.projectors = caps->projectors;
  info.width = caps->width;
  info.height = caps->height;
  info.fps = caps->fps;
  info.compressionsMask = caps->compressionsMask;
  info.rigJson = caps->rigJson;
  auto rig = config::parseRig(info.rigJson);
  if (!rig) {
    return Fail(where + ": the device's rig is invalid: " + rig.error().message());
  }
  info.rig = std::move(*rig);
  if (auto mismatch = announcementMismatch(info)) {
    return Fail(where + ": " + *mismatch);
  }
  return client;
}

std::expected<void, std::string> DeviceClient::send(
    const protocol::ProtocolResult<std::span<const std::byte>>& message) {
  if (!message) {
    return Fail(std::string("cannot encode a request: ") + message.error().message);
  }
  return socket_.sendAll(*message, std::chrono::milliseconds(5000));
}

std::expected<void, std::string> DeviceClient::startStream(protocol::Compression compression,
                                                           bool confidence) {
  return send(protocol::encode(
      protocol::StartStream{.compression = compression, .confidence = confidence}, out_));
}

std::expected<void, std::string> DeviceClient::stopStream() {
  return send(protocol::encodeEmpty(MessageType::kStopStream, out_));
}

std::expected<void, std::string> DeviceClient::requestStatistics() {
  return send(protocol::encodeEmpty(MessageType::kGetStatistics, out_));
}

DeviceClient::NextMessage DeviceClient::nextMessage(
    std::chrono::steady_clock::time_point deadline) {
  while (true) {
    while (true) {
      const auto next = parser_->next();
      if (!next) {
        continue;  // counted by the parser; it has skipped the bad bytes
      }
      const std::optional<protocol::Message>& parsed = *next;
      if (!parsed.has_value()) {
        break;
      }
      const protocol::Message& message = *parsed;
      return std::pair{message.type,
                       std::vector<std::byte>(message.payload.begin(), message.payload.end())};
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      return std::nullopt;
    }
    const auto got = socket_.receiveSome(parser_->writable(), left);
    if (!got) {
      return Fail(got.error());
    }
    parser_->commit(*got);
  }
}

std::expected<DeviceEvent, std::string> DeviceClient::next(std::chrono::milliseconds timeout) {
  auto message = nextMessage(timeout);
  if (!message) {
    return Fail(message.error());
  }
  const auto& got = *message;
  if (!got.has_value()) {
    return DeviceEvent{};
  }
  const auto& [type, payload] = *got;
  switch (type) {
    case MessageType::kRangeFrame:
    case MessageType::kRangeFrameConfidence: {
      auto received = receiveRangeFrame(payload, {info_.cameras, info_.width, info_.height},
                                        hal::SteadyClock().nowNs(), type);
      if (!received) {
        return Fail(received.error());
      }
      DeviceEvent event;
      event.kind = DeviceEvent::Kind::kFrame;
      event.frame = std::move(*received);
      return event;
    }
    case MessageType::kStatistics: {
      const auto stats = protocol::decodeStatistics(payload);
      if (!stats) {
        return Fail(std::string("bad statistics: ") + stats.error().message);
      }
      DeviceEvent event;
      event.kind = DeviceEvent::Kind::kStatistics;
      event.statistics = *stats;
      return event;
    }
    case MessageType::kError:
      return Fail(deviceError(payload));
    default:
      return DeviceEvent{};  // nothing the host waits for here
  }
}

std::expected<RawCapture, std::string> DeviceClient::captureRaw(std::uint32_t projectorsMask,
                                                                std::chrono::milliseconds timeout) {
  if (projectorsMask >> static_cast<unsigned>(info_.projectors) != 0) {
    return Fail("capture-raw: the device has " + std::to_string(info_.projectors) +
                " projectors; mask " + std::to_string(projectorsMask) + " names others");
  }
  auto assembler =
      RawFrameAssembler::create({info_.cameras, info_.width, info_.height}, projectorsMask);
  if (!assembler) {
    return Fail(assembler.error());
  }
  if (auto sent = send(protocol::encode(protocol::CaptureRaw{projectorsMask}, out_)); !sent) {
    return Fail(sent.error());
  }
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!assembler->complete()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    const auto silent = [&] {
      return Fail("no raw frames from the device within " + std::to_string(timeout.count()) +
                  " ms; firmware " + info_.firmwareVersion +
                  " may predate raw capture (capture-raw, docs/protocol.md): update it");
    };
    if (left.count() <= 0) {
      return silent();
    }
    auto message = nextMessage(left);
    if (!message) {
      return Fail(message.error());
    }
    const auto& got = *message;
    if (!got.has_value()) {
      return silent();
    }
    const auto& [type, payload] = *got;
    if (type == MessageType::kError) {
      const auto error = protocol::decodeError(payload);
      if (error && std::string_view(error->text).find("does not know") != std::string_view::npos) {
        return Fail("the device's firmware " + info_.firmwareVersion +
                    " cannot capture raw frames (it does not know capture-raw): update it");
      }
      return Fail(deviceError(payload));
    }
    if (type != MessageType::kRawFrame) {
      continue;  // range frames and statistics of a stream
    }
    if (auto added = assembler->add(payload); !added) {
      return Fail(added.error());
    }
  }
  return assembler->take();
}

std::expected<std::string, std::string> DeviceClient::getConfig(std::chrono::milliseconds timeout) {
  if (auto sent = send(protocol::encodeEmpty(MessageType::kGetConfig, out_)); !sent) {
    return Fail(sent.error());
  }
  return awaitConfig(timeout, "get-config");
}

std::expected<std::string, std::string> DeviceClient::setConfig(protocol::SetConfigMode mode,
                                                                std::string_view json,
                                                                std::chrono::milliseconds timeout) {
  std::vector<std::byte> message(protocol::kHeaderBytes + 8 + json.size());
  if (auto sent = send(protocol::encode(protocol::SetConfig{mode, json}, message)); !sent) {
    return Fail(sent.error());
  }
  return awaitConfig(timeout, "set-config");
}

std::expected<std::string, std::string> DeviceClient::awaitConfig(std::chrono::milliseconds timeout,
                                                                  std::string_view request) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    auto message = nextMessage(deadline);
    if (!message) {
      return Fail(message.error());
    }
    const auto& got = *message;
    if (!got.has_value()) {
      return Fail("no answer to " + std::string(request) + " within " +
                  std::to_string(timeout.count()) + " ms");
    }
    const auto& [type, payload] = *got;
    if (type == MessageType::kError) {
      const auto error = protocol::decodeError(payload);
      if (error && std::string_view(error->text).find("does not know") != std::string_view::npos) {
        return Fail("the device's firmware " + info_.firmwareVersion +
                    " has no settings to change (it does not know " + std::string(request) +
                    "): update it");
      }
      return Fail(deviceError(payload));
    }
    if (type == MessageType::kConfig) {
      const auto config = protocol::decodeConfig(payload);
      if (!config) {
        return Fail(std::string("bad config message: ") + config.error().message);
      }
      return std::string(config->json);
    }
  }
}

}  // namespace smx::host
