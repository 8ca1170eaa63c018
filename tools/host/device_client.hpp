#pragma once

#include <chrono>
#include <cstdint>
#include <expected>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "device_socket.hpp"
#include "range_frame.hpp"
#include "raw_frames.hpp"
#include "smx/algo/rig.hpp"
#include "smx/net/tcp_client.hpp"
#include "smx/protocol/messages.hpp"
#include "smx/protocol/stream_parser.hpp"
#include "smx/protocol/update_messages.hpp"

// The host tool's side of the protocol (docs/protocol.md): connect, hello → capabilities,
// start/stop the stream, read range frames and statistics, capture raw frames. Errors are
// messages for the user.
namespace smx::host {

struct DeviceInfo {
  std::string address;  // host:port as connected
  std::string board;
  std::string firmwareVersion;
  std::string halBackend;
  double depthUnitM = 1e-4;
  int cameras = 0;
  int projectors = 0;
  int width = 0;
  int height = 0;
  int fps = 0;
  std::uint8_t compressionsMask = 0;
  std::string rigJson;
  algo::Rig rig;
};

// What next() found: a range frame, the device's statistics, or nothing before the timeout.
struct DeviceEvent {
  enum class Kind : std::uint8_t { kNothing, kFrame, kStatistics };
  Kind kind = Kind::kNothing;
  ReceivedFrame frame;              // kFrame
  protocol::Statistics statistics;  // kStatistics
};

// A firmware upload that did not end installed: refused by the device (error code 6: the bundle
// is the problem), or the connection or the device failed.
struct FlashFailure {
  bool refused = false;
  std::string message;
};

struct UpdateStatusReport {
  protocol::UpdateOutcomeCode outcome = protocol::UpdateOutcomeCode::kNone;
  std::string runningSlot;
  std::string runningVersion;
  std::string updateVersion;
  std::string reason;
};

// A turntable request that did not end with the table's state: `absent` when the device has no
// turntable (its board has none, or its firmware predates turntables), else why it failed.
struct TurntableFailure {
  bool absent = false;
  std::string message;
};

class DeviceClient {
 public:
  [[nodiscard]] static std::expected<DeviceClient, std::string> connect(
      const std::string& address, std::chrono::milliseconds timeout);

  [[nodiscard]] const DeviceInfo& info() const { return info_; }
  // `confidence`: each frame with its confidence plane (a device too old for it refuses).
  [[nodiscard]] std::expected<void, std::string> startStream(protocol::Compression compression,
                                                             bool confidence = false);
  [[nodiscard]] std::expected<void, std::string> stopStream();
  [[nodiscard]] std::expected<void, std::string> requestStatistics();
  [[nodiscard]] std::expected<DeviceEvent, std::string> next(std::chrono::milliseconds timeout);
  // One raw frame per camera with exactly the projectors of `projectorsMask` lit (bit i: the
  // rig's projector i). Range frames and statistics that arrive meanwhile are skipped. A device
  // that refuses, or says nothing within `timeout`, is an error saying so.
  [[nodiscard]] std::expected<RawCapture, std::string> captureRaw(
      std::uint32_t projectorsMask, std::chrono::milliseconds timeout);
  // The settings the device runs with, a stripemux-config/1 document (docs/config.md).
  [[nodiscard]] std::expected<std::string, std::string> getConfig(
      std::chrono::milliseconds timeout);
  // Changes settings: the device checks and stores them, answers with the settings it will run
  // with, and restarts with them (this connection ends). A refusal names the setting.
  [[nodiscard]] std::expected<std::string, std::string> setConfig(
      protocol::SetConfigMode mode, std::string_view json, std::chrono::milliseconds timeout);
  // The turntable's state (device_client_turntable.cpp); present is false on a board without one.
  [[nodiscard]] std::expected<protocol::TurntableState, TurntableFailure> turntableStatus(
      std::chrono::milliseconds timeout);
  // Turns the table by (kRelative) or to (kAbsolute) `angleUdeg` and returns its state once it
  // has settled: frames captured after `settledNs` (device clock) see the table still.
  [[nodiscard]] std::expected<protocol::TurntableState, TurntableFailure> turnTurntable(
      protocol::TurnMode mode, std::int64_t angleUdeg, std::chrono::milliseconds timeout);
  // The owner's encrypted channel (a device this host paired with), or the clear.
  [[nodiscard]] bool encrypted() const { return socket_.encrypted(); }
  // Uploads a firmware bundle (device_client_update.cpp): `sent` is told the bytes sent so far,
  // `step` each installation step the device reports. Ends when the device says it restarts.
  [[nodiscard]] std::expected<void, FlashFailure> flash(
      std::span<const std::byte> bundle,
      const std::function<void(std::uint64_t sent, std::uint64_t total)>& sent,
      const std::function<void(const protocol::FlashProgress&)>& step,
      std::chrono::milliseconds timeout);
  [[nodiscard]] std::expected<UpdateStatusReport, std::string> updateStatus(
      std::chrono::milliseconds timeout);
  // Bad messages from the device so far (skipped).
  [[nodiscard]] std::uint64_t protocolErrors() const { return parser_->counters().errors; }
  void close() { socket_.close(); }

 private:
  DeviceClient(DeviceSocket socket, std::string address);
  [[nodiscard]] std::expected<void, std::string> send(
      const protocol::ProtocolResult<std::span<const std::byte>>& message);
  // A refusal (error) the device sent during an upload, without waiting; nullopt: none yet.
  [[nodiscard]] std::optional<FlashFailure> flashRefusal();
  // The config message that answers a get-config or set-config.
  [[nodiscard]] std::expected<std::string, std::string> awaitConfig(
      std::chrono::milliseconds timeout, std::string_view request);
  // The turntable message that answers `request`.
  [[nodiscard]] std::expected<protocol::TurntableState, TurntableFailure> awaitTurntable(
      std::chrono::milliseconds timeout, std::string_view request);
  // The next whole message (copied), or nullopt when none came by the deadline (or in timeout).
  using NextMessage =
      std::expected<std::optional<std::pair<protocol::MessageType, std::vector<std::byte>>>,
                    std::string>;
  [[nodiscard]] NextMessage nextMessage(std::chrono::steady_clock::time_point deadline);
  [[nodiscard]] NextMessage nextMessage(std::chrono::milliseconds timeout) {
    return nextMessage(std::chrono::steady_clock::now() + timeout);
  }

  DeviceSocket socket_;
  std::unique_ptr<protocol::StreamParser> parser_;
  std::vector<std::byte> out_;
  DeviceInfo info_;
};

}  // namespace smx::host
