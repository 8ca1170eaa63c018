// The turntable: requests on the network thread, moves in the capture loop between captures
// (a move blocks for seconds; no range frames are made meanwhile), answers once it settled.
#include <algorithm>
#include <array>
#include <cstdio>

#include "smx/device/device.hpp"
#include "smx/hal/turntable_motion.hpp"

namespace smx::device {

protocol::TurntableState Device::turntableState() const {
  const hal::Turntable* table = hal_.turntable;
  if (table == nullptr) {
    return {};
  }
  const std::int64_t position = table->position();
  return protocol::TurntableState{.present = true,
                                  .stepsPerTurn = static_cast<std::uint32_t>(table->stepsPerTurn()),
                                  .position = position,
                                  .angleUdeg = hal::angleMicroDeg(position, table->stepsPerTurn()),
                                  .settledNs = settledNs_};
}

void Device::onTurntable(const protocol::Message& message) {
  std::array<std::byte, 256> reply{};
  const auto refuse = [&](protocol::ErrorCode code, const char* text) {
    ++counters_.protocolErrors;
    if (const auto error = protocol::encode(protocol::ErrorMessage{code, text}, reply)) {
      sendControl(*error);
    }
  };
  if (message.type == protocol::MessageType::kGetTurntable) {
    if (!protocol::decodeEmpty(message.payload)) {
      refuse(protocol::ErrorCode::kBadRequest, "payload on a message that has none");
    } else if (!helloSeen_) {
      refuse(protocol::ErrorCode::kBadRequest, "get-turntable before hello");
    } else if (const auto state = protocol::encode(turntableState(), reply)) {
      sendControl(*state);
    }
    return;
  }
  const auto request = protocol::decodeTurnTurntable(message.payload);
  if (!request) {
    refuse(protocol::ErrorCode::kBadRequest, request.error().message);
    return;
  }
  if (!helloSeen_) {
    refuse(protocol::ErrorCode::kBadRequest, "turn-turntable before hello");
    return;
  }
  if (hal_.turntable == nullptr) {
    refuse(protocol::ErrorCode::kBadRequest, "turn-turntable: the board has no turntable");
    return;
  }
  if (turnState_ != TurnState::kIdle) {
    refuse(protocol::ErrorCode::kBusy, "turn-turntable: the previous move is not over yet");
    return;
  }
  // Only the capture loop moves the table, and it is idle: the position is steady.
  const auto steps =
      hal::stepsToMove(hal_.turntable->position(), hal_.turntable->stepsPerTurn(),
                       request->mode == protocol::TurnMode::kAbsolute, request->angleUdeg);
  if (!steps) {
    refuse(protocol::ErrorCode::kBadRequest,
           "turn-turntable: the move is beyond 2^31 steps; turn by less");
    return;
  }
  turnSteps_ = *steps;
  turnConnection_ = counters_.connections.load();
  turnState_ = TurnState::kRequested;  // publishes the steps to the capture loop
}

bool Device::serveTurn() {
  auto requested = TurnState::kRequested;
  if (hal_.turntable == nullptr ||
      !turnState_.compare_exchange_strong(requested, TurnState::kMoving)) {
    return false;
  }
  finishCapture();  // the frame taken before the move goes out before its answer
  const auto moved = hal_.turntable->move(turnSteps_);
  turnFailed_ = !moved;
  if (!moved) {
    turnError_ = moved.error();
    ++counters_.captureErrors;
  }
  // Frames of a camera that kept streaming through the move carry earlier timestamps.
  settledNs_ = hal_.clock.nowNs();
  ++counters_.turns;
  turnState_ = TurnState::kDone;  // publishes the outcome to the network loop
  return true;
}

void Device::answerTurn() {
  if (turnState_ != TurnState::kDone) {
    return;
  }
  if (turnConnection_ == counters_.connections && hal_.link.connected()) {
    std::array<std::byte, 320> reply{};
    if (!turnFailed_) {
      if (const auto state = protocol::encode(turntableState(), reply)) {
        sendControl(*state);
      }
    } else {
      std::array<char, 256> text{};
      const int length = std::snprintf(text.data(), text.size(), "turn-turntable: %s (%s)",
                                       turnError_.message, hal::toString(turnError_.code));
      const protocol::ErrorMessage error{
          protocol::ErrorCode::kInternal,
          std::string_view(text.data(), static_cast<std::size_t>(std::clamp(length, 0, 255)))};
      if (const auto encoded = protocol::encode(error, reply)) {
        sendControl(*encoded);
      }
    }
  }
  turnState_ = TurnState::kIdle;  // answered, or for a host that has left
}

}  // namespace smx::device
