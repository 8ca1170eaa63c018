// The network loop: one host at a time, control replies before queued frames, nothing blocks.
#include <cstring>

#include "smx/device/device.hpp"

namespace smx::device {

namespace {
constexpr std::int64_t kNetworkTickNs = 2'000'000;  // bounds the latency of a queued frame
}  // namespace

protocol::Statistics Device::statistics() const {
  const std::uint64_t decoded = counters_.framesDecoded;
  return protocol::Statistics{
      .uptimeMs = static_cast<std::uint64_t>((hal_.clock.nowNs() - startNs_) / 1'000'000),
      .framesCaptured = counters_.framesCaptured,
      .framesDecoded = decoded,
      .framesSent = counters_.framesSent,
      .framesDropped = queue_.dropped(),
      .captureErrors = counters_.captureErrors,
      .protocolErrors = counters_.protocolErrors,
      .decodeTimeUsLast = counters_.decodeTimeUsLast,
      .decodeTimeUsMean =
          static_cast<std::uint32_t>(decoded == 0 ? 0 : counters_.decodeTimeUsTotal / decoded)};
}

protocol::Statistics Device::statisticsForHost() const {
  protocol::Statistics stats = statistics();
  stats.framesSent -= sentAtConnect_;
  stats.framesDropped -= droppedAtConnect_;
  stats.protocolErrors -= protocolErrorsAtConnect_;
  return stats;
}

void Device::sendControl(std::span<const std::byte> message) {
  if (control_.size() - controlSize_ < message.size()) {
    ++counters_.protocolErrors;  // a host that asks faster than it reads loses replies
    return;
  }
  std::memcpy(control_.data() + controlSize_, message.data(), message.size());
  controlSize_ += message.size();
}

void Device::onMessage(const protocol::Message& message) {
  using protocol::MessageType;
  std::array<std::byte, 512> reply{};
  const auto refuse = [&](protocol::ErrorCode code, const char* text) {
    ++counters_.protocolErrors;
    if (const auto error = protocol::encode(protocol::ErrorMessage{code, text}, reply)) {
      sendControl(*error);
    }
  };
  switch (message.type) {
    case MessageType::kHello:
      if (!protocol::decodeHello(message.payload)) {
        refuse(protocol::ErrorCode::kBadRequest, "malformed hello");
        return;
      }
      helloSeen_ = true;
      sendControl(capabilities_);
      return;
    case MessageType::kStartStream: {
      const auto start = protocol::decodeStartStream(message.payload);
      if (!start) {
        refuse(protocol::ErrorCode::kBadRequest, start.error().message);
      } else if (!helloSeen_) {
        refuse(protocol::ErrorCode::kBadRequest, "start-stream before hello");
      } else if ((options_.compressionsMask & (1U << static_cast<unsigned>(start->compression))) ==
                 0) {
        refuse(protocol::ErrorCode::kBadRequest,
               "start-stream: the device's settings do not allow that compression");
      } else {
        compression_ = start->compression;
        confidence_ = start->confidence;
        streaming_ = true;
      }
      return;
    }
    case MessageType::kStopStream:
      streaming_ = false;
      queue_.clear();
      [[fallthrough]];
    case MessageType::kGetStatistics:
      if (!protocol::decodeEmpty(message.payload)) {
        refuse(protocol::ErrorCode::kBadRequest, "payload on a message that has none");
      } else if (const auto stats = protocol::encode(statisticsForHost(), reply)) {
        sendControl(*stats);
      }
      return;
    case MessageType::kCaptureRaw: {
      const auto request = protocol::decodeCaptureRaw(message.payload);
      if (!request) {
        refuse(protocol::ErrorCode::kBadRequest, request.error().message);
      } else if (!helloSeen_) {
        refuse(protocol::ErrorCode::kBadRequest, "capture-raw before hello");
      } else if ((request->projectorsMask & ~allProjectorsMask_) != 0) {
        refuse(protocol::ErrorCode::kBadRequest,
               "capture-raw: a projector bit beyond the board's projectors");
      } else if (rawState_ != RawState::kIdle) {
        refuse(protocol::ErrorCode::kBusy, "capture-raw: the previous raw capture is not sent yet");
      } else {
        // Only this thread leaves kIdle, so the mask is in place before the capture loop looks.
        rawMask_ = request->projectorsMask;
        rawConnection_ = counters_.connections.load();
        rawState_ = RawState::kRequested;
      }
      return;
    }
    case MessageType::kGetConfig:
      if (!protocol::decodeEmpty(message.payload)) {
        refuse(protocol::ErrorCode::kBadRequest, "payload on a message that has none");
      } else if (!helloSeen_) {
        refuse(protocol::ErrorCode::kBadRequest, "get-config before hello");
      } else {
        sendConfig(options_.configJson);
      }
      return;
    case MessageType::kSetConfig:
      onSetConfig(message);
      return;
    case MessageType::kGetTurntable:
    case MessageType::kTurnTurntable:
      onTurntable(message);
      return;
    case MessageType::kFlashBegin:
    case MessageType::kFlashData:
    case MessageType::kFlashEnd:
    case MessageType::kGetUpdateStatus:
      onFlash(message);
      return;
    default:
      refuse(protocol::ErrorCode::kBadRequest, "that message type is not for the device");
      return;
  }
}

void Device::sendConfig(std::string_view json) {
  if (const auto config = protocol::encode(protocol::ConfigMessage{json},
                                           std::span(control_).subspan(controlSize_))) {
    controlSize_ += config->size();
  } else {
    ++counters_.protocolErrors;  // replies were not read: the host loses this one too
  }
}

// Leaves the steady state: parsing and storing settings allocate, and the device restarts.
void Device::onSetConfig(const protocol::Message& message) {
  const auto refuse = [&](protocol::ErrorCode code, std::string_view text) {
    std::array<std::byte, 1024> reply{};
    const std::string_view cut = text.substr(0, reply.size() - 64);
    if (const auto error = protocol::encode(protocol::ErrorMessage{code, cut}, reply)) {
      sendControl(*error);
    }
  };
  const auto request = protocol::decodeSetConfig(message.payload);
  if (!request) {
    ++counters_.protocolErrors;
    refuse(protocol::ErrorCode::kBadRequest, request.error().message);
  } else if (!helloSeen_) {
    refuse(protocol::ErrorCode::kBadRequest, "set-config before hello");
  } else if (!options_.setConfig) {
    refuse(protocol::ErrorCode::kBadRequest,
           "set-config: this device keeps no settings (stripemuxd runs without --state)");
  } else if (restartPending_) {
    refuse(protocol::ErrorCode::kBusy, "set-config: the device is restarting with new settings");
  } else if (auto stored = options_.setConfig(*request); !stored) {
    refuse(protocol::ErrorCode::kBadRequest, "set-config: " + stored.error());
  } else {
    streaming_ = false;
    queue_.clear();
    sendConfig(*stored);
    restartPending_ = true;
  }
}

void Device::dropConnection() {
  hal_.link.disconnect();
  streaming_ = false;
  if (sendingFrame_ && !sending_.empty()) {
    queue_.finishSend();  // lost with the connection, not sent
  }
  sending_ = {};
  sendingFrame_ = false;
  sendingRaw_ = false;
  controlSize_ = 0;
  queue_.clear();
  // A raw capture asked for by this host is not sent to the next (the capture loop may still
  // be taking it: pumpSend() drops it by its connection number).
  for (const RawState done : {RawState::kRequested, RawState::kReady, RawState::kSending}) {
    auto state = done;
    (void)rawState_.compare_exchange_strong(state, RawState::kIdle);
  }
  // A move not started yet is not made; one under way ends, and answerTurn() drops its answer.
  auto turn = TurnState::kRequested;
  (void)turnState_.compare_exchange_strong(turn, TurnState::kIdle);
}

void Device::pumpSend(std::int64_t nowNs) {
  while (hal_.link.connected()) {
    if (sending_.empty()) {
      sent_ = 0;
      if (controlSize_ > 0) {
        sending_ = std::span(control_).first(controlSize_);
        sendingFrame_ = false;
      } else if (rawState_ == RawState::kReady) {
        if (rawConnection_ != counters_.connections) {
          rawState_ = RawState::kIdle;  // for a host that has left
          continue;
        }
        rawState_ = RawState::kSending;
        sending_ = std::span(raw_).first(rawSize_);
        sendingFrame_ = false;
        sendingRaw_ = true;
      } else if (streaming_) {
        sending_ = queue_.beginSend();
        sendingFrame_ = !sending_.empty();
        if (sending_.empty()) {
          lastSentNs_ = nowNs;  // nothing waits: not stalled
          return;
        }
      } else {
        lastSentNs_ = nowNs;
        return;
      }
    }
    const auto n = hal_.link.sendSome(sending_.subspan(sent_));
    if (!n) {
      dropConnection();
      return;
    }
    if (*n == 0) {
      return;  // the host is not reading: the queue absorbs (and drops) what capture makes
    }
    lastSentNs_ = nowNs;
    sent_ += *n;
    if (sent_ < sending_.size()) {
      continue;
    }
    if (sendingFrame_) {
      queue_.finishSend();
      ++counters_.framesSent;
    } else if (sendingRaw_) {
      sendingRaw_ = false;
      rawState_ = RawState::kIdle;
    } else {
      // Replies added while these were sent move to the front.
      std::memmove(control_.data(), control_.data() + sent_, controlSize_ - sent_);
      controlSize_ -= sent_;
    }
    sending_ = {};
    sendingFrame_ = false;
  }
}

void Device::serviceNetwork(std::int64_t timeoutNs) {
  hal::Link& link = hal_.link;
  if (!link.connected()) {
    if (restartPending_) {
      restartDue_ = true;  // the host left before its answer was out; the settings are stored
      return;
    }
    if (hadClient_) {
      dropConnection();  // the link noticed first that the host left
      hadClient_ = false;
    }
    if (link.acceptClient(timeoutNs)) {
      hadClient_ = true;
      parser_.reset();
      helloSeen_ = false;
      flashState_ = FlashState::kIdle;
      lastReceivedNs_ = lastSentNs_ = hal_.clock.nowNs();
      sentAtConnect_ = counters_.framesSent;
      droppedAtConnect_ = queue_.dropped();
      protocolErrorsAtConnect_ = counters_.protocolErrors;
      ++counters_.connections;
    }
    return;
  }
  const bool wantWrite = !sending_.empty() || controlSize_ > 0 || rawState_ == RawState::kReady ||
                         turnState_ == TurnState::kDone || (streaming_ && queue_.queued() > 0);
  (void)link.waitForIo(wantWrite, timeoutNs);

  const std::int64_t now = hal_.clock.nowNs();
  const auto received = link.receiveSome(parser_.writable(), 0);
  if (!received) {
    dropConnection();
    return;
  }
  if (*received > 0) {
    lastReceivedNs_ = now;
  }
  parser_.commit(*received);
  while (true) {
    const auto next = parser_.next();
    if (!next) {
      ++counters_.protocolErrors;
      std::array<std::byte, 256> reply{};
      if (next.error().code == protocol::ProtocolErrc::kUnsupportedVersion) {
        if (const auto error =
                protocol::encode(protocol::ErrorMessage{protocol::ErrorCode::kUnsupportedVersion,
                                                        "this device speaks protocol version 1"},
                                 reply)) {
          sendControl(*error);
        }
      } else if (next.error().code == protocol::ProtocolErrc::kUnknownType) {
        // A newer host asks for something this firmware cannot do: say so rather than stay mute.
        if (const auto error = protocol::encode(
                protocol::ErrorMessage{protocol::ErrorCode::kBadRequest,
                                       "a message type this firmware does not know"},
                reply)) {
          sendControl(*error);
        }
      }
      continue;
    }
    const std::optional<protocol::Message>& message = *next;
    if (!message.has_value()) {
      break;
    }
    onMessage(*message);
  }
  answerTurn();
  pumpSend(now);
  if (restartPending_ && controlSize_ == 0 && sending_.empty()) {
    restartDue_ = true;  // the answer is out: the host knows the settings are stored
  }
  if (idle(now)) {
    ++counters_.idleDisconnects;
    dropConnection();
  }
}

bool Device::idle(std::int64_t nowNs) const {
  const std::int64_t timeout = options_.idleTimeoutNs;
  if (timeout <= 0 || !hal_.link.connected()) {
    return false;
  }
  // A streaming host need not send anything, nor one waiting for the turntable to settle; every
  // host must read what it is sent.
  const bool silent =
      !streaming_ && turnState_ == TurnState::kIdle && nowNs - lastReceivedNs_ > timeout;
  const bool stalled = nowNs - lastSentNs_ > timeout;
  return silent || stalled;
}

void Device::runNetwork(const std::atomic<bool>& stop) {
  while (!stop && !restartDue_) {
    serviceNetwork(kNetworkTickNs);
  }
  if (hal_.link.connected()) {
    // Say goodbye with the counters, as far as the socket takes them now.
    std::array<std::byte, 256> reply{};
    if (const auto stats = protocol::encode(statisticsForHost(), reply)) {
      (void)hal_.link.sendSome(*stats);
    }
    hal_.link.disconnect();
  }
}

}  // namespace smx::device
