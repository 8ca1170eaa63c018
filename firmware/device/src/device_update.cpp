// The firmware upload on the network thread (docs/update.md#upload): the device checks the
// order of the messages and the byte count; what the bytes are and where they go is the
// daemon's (DeviceOptions::update).
#include "smx/device/device.hpp"

namespace smx::device {

void Device::onFlash(const protocol::Message& message) {
  using protocol::MessageType;
  const auto send = [&](const auto& encoded) {
    if (encoded) {
      sendControl(*encoded);
    }
  };
  const auto refuse = [&](protocol::ErrorCode code, std::string_view text) {
    std::array<std::byte, 1024> reply{};
    send(protocol::encode(protocol::ErrorMessage{code, text.substr(0, reply.size() - 64)}, reply));
  };
  const auto refuseUpdate = [&](std::string_view text) {
    flashState_ = FlashState::kIdle;
    refuse(protocol::ErrorCode::kUpdateRefused, text);
  };
  const UpdateHooks& hooks = options_.update;
  if (!helloSeen_) {
    ++counters_.protocolErrors;
    refuse(protocol::ErrorCode::kBadRequest, "a firmware update message before hello");
    return;
  }
  if (!hooks.begin || !hooks.data || !hooks.end || !hooks.status) {
    refuseUpdate("this device takes no updates (stripemuxd runs without --state)");
    return;
  }
  if (restartPending_) {
    refuse(protocol::ErrorCode::kBusy, "the device is restarting");
    return;
  }
  switch (message.type) {
    case MessageType::kFlashBegin: {
      const auto begin = protocol::decodeFlashBegin(message.payload);
      if (!begin) {
        ++counters_.protocolErrors;
        refuse(protocol::ErrorCode::kBadRequest, begin.error().message);
      } else if (auto opened = hooks.begin(begin->size); !opened) {
        refuseUpdate(opened.error());
      } else {
        flashState_ = FlashState::kReceiving;
        flashSize_ = begin->size;
        flashReceived_ = 0;
      }
      return;
    }
    case MessageType::kFlashData: {
      if (flashState_ == FlashState::kFailed) {
        return;  // said once; the rest of the upload is dropped
      }
      const auto data = protocol::decodeFlashData(message.payload);
      if (!data || flashState_ != FlashState::kReceiving) {
        ++counters_.protocolErrors;
        refuse(protocol::ErrorCode::kBadRequest,
               data ? "flash-data without flash-begin" : data.error().message);
      } else if (data->bytes.size() > flashSize_ - flashReceived_) {
        refuseUpdate("flash-data: more bytes than flash-begin announced");
        flashState_ = FlashState::kFailed;
      } else if (auto written = hooks.data(data->bytes); !written) {
        refuseUpdate(written.error());
        flashState_ = FlashState::kFailed;
      } else {
        flashReceived_ += data->bytes.size();
      }
      return;
    }
    case MessageType::kFlashEnd: {
      if (!protocol::decodeEmpty(message.payload) || flashState_ != FlashState::kReceiving) {
        ++counters_.protocolErrors;
        const bool failed = flashState_ == FlashState::kFailed;
        flashState_ = FlashState::kIdle;
        refuse(failed ? protocol::ErrorCode::kUpdateRefused : protocol::ErrorCode::kBadRequest,
               failed ? "flash-end: the upload failed before" : "flash-end without flash-begin");
        return;
      }
      flashState_ = FlashState::kIdle;
      if (flashReceived_ != flashSize_) {
        refuseUpdate("flash-end: " + std::to_string(flashReceived_) + " of " +
                     std::to_string(flashSize_) + " bytes received");
        return;
      }
      const auto progress = [&](protocol::FlashStep step, std::string_view text) {
        std::array<std::byte, 1024> reply{};
        send(protocol::encode(
            protocol::FlashProgress{step, flashReceived_, text.substr(0, reply.size() - 64)},
            reply));
      };
      if (auto installed = hooks.end(progress); !installed) {
        refuseUpdate(installed.error());
        return;
      }
      // As after set-config: the answer goes out, then the loops stop and the daemon exits.
      updateDue_ = true;
      restartPending_ = true;
      return;
    }
    default: {
      const UpdateStatusInfo status = hooks.status();
      const std::string_view reason = status.reason;
      std::array<std::byte, 2048> reply{};
      send(protocol::encode(
          protocol::UpdateStatus{status.outcome, status.runningSlot, status.runningVersion,
                                 status.updateVersion, reason.substr(0, 1024)},
          reply));
      return;
    }
  }
}

}  // namespace smx::device
