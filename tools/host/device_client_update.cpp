// The firmware upload and the update status (docs/protocol.md, messages 15–20).
#include <algorithm>

#include "device_client.hpp"

namespace smx::host {
namespace {

using protocol::MessageType;

FlashFailure failure(std::span<const std::byte> payload) {
  const auto error = protocol::decodeError(payload);
  if (!error) {
    return {false, "the device reported an error (unreadable)"};
  }
  return {error->code == protocol::ErrorCode::kUpdateRefused,
          "the device refused: " + std::string(error->text)};
}

}  // namespace

std::optional<FlashFailure> DeviceClient::flashRefusal() {
  while (true) {
    auto message = nextMessage(std::chrono::milliseconds(0));
    if (!message) {
      return FlashFailure{false, message.error()};
    }
    const auto& got = *message;
    if (!got.has_value()) {
      return std::nullopt;
    }
    if (got->first == MessageType::kError) {
      return failure(got->second);
    }
  }
}

std::expected<void, FlashFailure> DeviceClient::flash(
    std::span<const std::byte> bundle,
    const std::function<void(std::uint64_t, std::uint64_t)>& sent,
    const std::function<void(const protocol::FlashProgress&)>& step,
    std::chrono::milliseconds timeout) {
  const auto fail = [](std::string text) {
    return std::unexpected(FlashFailure{false, std::move(text)});
  };
  std::vector<std::byte> message(protocol::kHeaderBytes + protocol::kFlashChunkBytes);
  if (auto begun = send(protocol::encode(protocol::FlashBegin{bundle.size()}, message)); !begun) {
    return fail(begun.error());
  }
  for (std::size_t done = 0; done < bundle.size();) {
    if (auto refused = flashRefusal()) {
      return std::unexpected(*refused);
    }
    const std::size_t n = std::min(protocol::kFlashChunkBytes, bundle.size() - done);
    if (auto chunk = send(protocol::encode(protocol::FlashData{bundle.subspan(done, n)}, message));
        !chunk) {
      return fail(chunk.error());
    }
    done += n;
    sent(done, bundle.size());
  }
  if (auto ended = send(protocol::encodeEmpty(MessageType::kFlashEnd, message)); !ended) {
    return fail(ended.error());
  }
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    auto next = nextMessage(deadline);
    if (!next) {
      return fail(next.error());
    }
    const auto& got = *next;
    if (!got.has_value()) {
      return fail("the device did not finish the installation within " +
                  std::to_string(timeout.count() / 1000) + " s");
    }
    const auto& [type, payload] = *got;
    if (type == MessageType::kError) {
      return std::unexpected(failure(payload));
    }
    if (type == MessageType::kFlashProgress) {
      const auto progress = protocol::decodeFlashProgress(payload);
      if (!progress) {
        return fail(std::string("bad flash-progress message: ") + progress.error().message);
      }
      step(*progress);
      if (progress->step == protocol::FlashStep::kRestarting) {
        return {};
      }
    }
  }
}

std::expected<UpdateStatusReport, std::string> DeviceClient::updateStatus(
    std::chrono::milliseconds timeout) {
  std::array<std::byte, protocol::kHeaderBytes> message{};
  if (auto asked = send(protocol::encodeEmpty(MessageType::kGetUpdateStatus, message)); !asked) {
    return std::unexpected(asked.error());
  }
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    auto next = nextMessage(deadline);
    if (!next) {
      return std::unexpected(next.error());
    }
    const auto& got = *next;
    if (!got.has_value()) {
      return std::unexpected("no answer to get-update-status within " +
                             std::to_string(timeout.count()) + " ms");
    }
    const auto& [type, payload] = *got;
    if (type == MessageType::kError) {
      return std::unexpected(failure(payload).message);
    }
    if (type == MessageType::kUpdateStatus) {
      const auto status = protocol::decodeUpdateStatus(payload);
      if (!status) {
        return std::unexpected(std::string("bad update-status message: ") + status.error().message);
      }
      return UpdateStatusReport{status->outcome, std::string(status->runningSlot),
                                std::string(status->runningVersion),
                                std::string(status->updateVersion), std::string(status->reason)};
    }
  }
}

}  // namespace smx::host
