// The turntable requests of DeviceClient (docs/protocol.md, messages 29-31).
#include <string>

#include "device_client.hpp"

namespace smx::host {

namespace {

using protocol::MessageType;
using Fail = std::unexpected<TurntableFailure>;

constexpr std::string_view kPredates =
    "the device has no turntable (its firmware predates turntables)";

}  // namespace

std::expected<protocol::TurntableState, TurntableFailure> DeviceClient::turntableStatus(
    std::chrono::milliseconds timeout) {
  if (auto sent = send(protocol::encodeEmpty(MessageType::kGetTurntable, out_)); !sent) {
    return Fail({false, sent.error()});
  }
  return awaitTurntable(timeout, "get-turntable");
}

std::expected<protocol::TurntableState, TurntableFailure> DeviceClient::turnTurntable(
    protocol::TurnMode mode, std::int64_t angleUdeg, std::chrono::milliseconds timeout) {
  if (auto sent = send(protocol::encode(protocol::TurnTurntable{mode, angleUdeg}, out_)); !sent) {
    return Fail({false, sent.error()});
  }
  return awaitTurntable(timeout, "turn-turntable");
}

std::expected<protocol::TurntableState, TurntableFailure> DeviceClient::awaitTurntable(
    std::chrono::milliseconds timeout, std::string_view request) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    auto message = nextMessage(deadline);
    if (!message) {
      return Fail({false, message.error()});
    }
    const auto& got = *message;
    if (!got.has_value()) {
      return Fail({false, "no answer to " + std::string(request) + " within " +
                              std::to_string(timeout.count()) + " ms"});
    }
    const auto& [type, payload] = *got;
    if (type == MessageType::kError) {
      const auto error = protocol::decodeError(payload);
      const std::string_view text = error ? error->text : std::string_view();
      // An old firmware does not know the message; a new one says its board has no table.
      if (text.find("does not know") != std::string_view::npos) {
        return Fail({true, std::string(kPredates)});
      }
      if (text.find("has no turntable") != std::string_view::npos) {
        return Fail({true, "the device has no turntable"});
      }
      return Fail({false, error ? "the device refused: " + std::string(text)
                                : std::string("the device reported an error (unreadable)")});
    }
    if (type == MessageType::kTurntable) {
      const auto state = protocol::decodeTurntable(payload);
      if (!state) {
        return Fail({false, std::string("bad turntable message: ") + state.error().message});
      }
      return *state;
    }
    // Range frames and statistics of a stream still draining are not the answer.
  }
}

}  // namespace smx::host
