#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/config/board_json.hpp"
#include "smx/device/background_job.hpp"
#include "smx/device/send_queue.hpp"
#include "smx/device/worker_pool.hpp"
#include "smx/hal/board_hal.hpp"
#include "smx/protocol/messages.hpp"
#include "smx/protocol/stream_parser.hpp"
#include "smx/protocol/update_messages.hpp"

// The appliance (docs/firmware.md): a capture loop that triggers the projectors, captures every
// camera, runs the pipeline and queues range frames, and a network loop that serves one host
// (hello → capabilities, start/stop stream, statistics, raw capture) and sends the queue. Each
// loop runs on its own thread; after create() neither allocates.
namespace smx::device {

// The last firmware update as the device reports it (update-status).
struct UpdateStatusInfo {
  protocol::UpdateOutcomeCode outcome = protocol::UpdateOutcomeCode::kNone;
  std::string runningSlot = "factory";
  std::string runningVersion;
  std::string updateVersion;
  std::string reason;
};

// The firmware update (docs/update.md), implemented by the daemon so that this library holds no
// update logic. Each runs on the network thread; unset, the flash messages are refused.
struct UpdateHooks {
  using Progress = std::function<void(protocol::FlashStep, std::string_view)>;
  // flash-begin: checks the size against the limits and the free space, opens the upload file.
  std::function<std::expected<void, std::string>(std::uint64_t size)> begin;
  // flash-data: appends a chunk to the upload file.
  std::function<std::expected<void, std::string>(std::span<const std::byte>)> data;
  // flash-end: verifies and installs, telling each step; then the device exits (updateDue()).
  std::function<std::expected<void, std::string>(const Progress&)> end;
  std::function<UpdateStatusInfo()> status;
};

struct DeviceOptions {
  std::string firmwareVersion = "0.0.0";
  std::size_t queueSlots = 4;  // range frames waiting for the host (all cameras)
  // Decoding threads (0: board.json's `threads`, else one per camera): the cameras in
  // parallel, and threads beyond one per camera split each camera's frame.
  int decodeThreads = 0;
  // The capture of the next frame overlaps the decoding of the last (board.json's `pipelined`):
  // more frames per second, each still as soon as it is decoded.
  bool pipelined = false;
  std::int64_t acquireTimeoutNs = 2'000'000'000;
  // A host that sends nothing while not streaming, or reads nothing while the device has data
  // for it, for this long is disconnected so that another can use the device (0: never).
  // Long enough for a person between two commands of a host program or a slow disk write on
  // the host; short enough that a forgotten or vanished host frees the scanner in half a minute.
  std::int64_t idleTimeoutNs = 30'000'000'000;
  algo::PipelineOptions pipeline;                           // depthUnitM is taken from the board
  std::uint8_t compressionsMask = (1U << 0U) | (1U << 1U);  // what start-stream may ask for
  // The settings the device runs with (stripemux-config/1), the answer to get-config.
  std::string configJson;
  // Checks and stores a set-config's change and returns the settings the device will run with
  // (or why not); the device then restarts with them (restartDue()). Runs on the network
  // thread; unset: set-config is refused.
  std::function<std::expected<std::string, std::string>(const protocol::SetConfig&)> setConfig;
  UpdateHooks update;
};

// Counters, readable from any thread while the loops run.
struct DeviceCounters {
  std::atomic<std::uint64_t> framesCaptured = 0;   // camera frames acquired
  std::atomic<std::uint64_t> framesDecoded = 0;    // range frames computed
  std::atomic<std::uint64_t> framesQueued = 0;     // range frames handed to the send queue
  std::atomic<std::uint64_t> framesSent = 0;       // range frames fully given to the link
  std::atomic<std::uint64_t> captureErrors = 0;    // timeouts, lost cameras, failed frames
  std::atomic<std::uint64_t> protocolErrors = 0;   // bad messages from the host
  std::atomic<std::uint64_t> connections = 0;      // hosts served so far
  std::atomic<std::uint64_t> idleDisconnects = 0;  // hosts dropped after the idle timeout
  std::atomic<std::uint64_t> rawCaptures = 0;      // raw captures served (capture-raw)
  std::atomic<std::uint64_t> turns = 0;            // turntable moves done (turn-turntable)
  std::atomic<std::uint64_t> decodeTimeUsTotal = 0;
  std::atomic<std::uint32_t> decodeTimeUsLast = 0;
};

class Device {
 public:
  // Init: pipelines and their arenas, the send queue, the capabilities message.
  [[nodiscard]] static std::expected<std::unique_ptr<Device>, std::string> create(
      const config::Board& board, hal::Hal hal, const DeviceOptions& options);
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  // One capture: trigger, acquire every camera, decode, queue (while a host streams). A camera
  // error is counted and returned; the caller goes on with the next capture. Pipelined, the
  // capture is decoded in the background while the next one is taken: captureOnce() returns
  // once the previous capture is decoded and this one's decoding has begun.
  [[nodiscard]] hal::HalResult<void> captureOnce();
  // Pipelined: waits for the capture being decoded and gives its frames back to the cameras.
  void finishCapture();
  // Serves a raw capture the host asked for, if one waits: lights the asked projectors, takes
  // one frame per camera and leaves the bands (or an error) for the network loop to send.
  // Returns whether one was served. Allocation-free.
  bool serveRawCapture();
  // Turns the turntable as a host asked, if a request waits: blocks for the move and its settle
  // time, then leaves the answer for the network loop. Returns whether one was served.
  // Allocation-free.
  bool serveTurn();
  // Runs serveRawCapture(), serveTurn() and captureOnce() until stop is set.
  void runCapture(const std::atomic<bool>& stop);
  // One round of the network loop: accept, receive and answer, send; waits at most timeoutNs.
  void serviceNetwork(std::int64_t timeoutNs);
  void runNetwork(const std::atomic<bool>& stop);

  [[nodiscard]] const DeviceCounters& counters() const { return counters_; }
  [[nodiscard]] std::uint64_t framesDropped() const { return queue_.dropped(); }
  // Since start-up, every host together (the daemon's status line).
  [[nodiscard]] protocol::Statistics statistics() const;
  // What the connected host is sent: frames sent and dropped and protocol errors count for its
  // connection only, the rest since start-up (docs/protocol.md, message 7).
  [[nodiscard]] protocol::Statistics statisticsForHost() const;
  [[nodiscard]] bool streaming() const { return streaming_; }
  // A set-config was stored and its answer sent: the owner of the loops stops them and creates
  // the device again with the new settings. runNetwork() returns when this turns true.
  [[nodiscard]] bool restartDue() const { return restartDue_; }
  // With restartDue(): a firmware update was installed; the daemon exits for the supervisor.
  [[nodiscard]] bool updateDue() const { return updateDue_; }
  // A host's capture-raw waits for the capture loop.
  [[nodiscard]] bool rawCaptureRequested() const { return rawState_ == RawState::kRequested; }
  // A host's turn-turntable waits for the capture loop.
  [[nodiscard]] bool turnRequested() const { return turnState_ == TurnState::kRequested; }
  [[nodiscard]] std::size_t arenaBytes() const;
  [[nodiscard]] const hal::Hal& hal() const { return hal_; }

 private:
  struct CameraSlot {
    std::vector<std::byte> memory;
    std::unique_ptr<algo::Arena> arena;
    std::unique_ptr<algo::CameraPipeline> pipeline;
    std::unique_ptr<WorkerPool> jobs;  // the parts of one frame
  };

  Device(const config::Board& board, hal::Hal hal, const DeviceOptions& options);
  struct Acquired {
    hal::HalResult<void> status;
    std::size_t count = 0;    // frames borrowed, from the first camera on
    bool triggered = false;   // the lines were lit
    std::string_view failed;  // what failed: "trigger lines" or the camera's id
  };
  // Lights `mask` and borrows one frame per camera into `frames`.
  Acquired acquireFrames(std::uint32_t mask, std::vector<hal::CameraFrame>& frames);
  void releaseFrames(const std::vector<hal::CameraFrame>& frames, std::size_t count) const;
  // Decodes (and queues) frames_[0, decodingCount_) as capture decodingNumber_.
  void decodeFrames();
  void decodeCamera(int camera);
  void queueRangeFrame(int camera, const hal::CameraFrame& frame, std::uint32_t decodeUs);
  // Captures with `mask` lit and writes the bands of every camera into raw_; returns their size
  // (an error message instead when a camera or the trigger fails).
  std::size_t captureRaw(std::uint32_t mask);
  std::size_t rawError(std::string_view what, const hal::HalError& error);
  void onMessage(const protocol::Message& message);
  void onSetConfig(const protocol::Message& message);
  void onFlash(const protocol::Message& message);  // device_update.cpp
  // get-turntable and turn-turntable (device_turntable.cpp).
  void onTurntable(const protocol::Message& message);
  [[nodiscard]] protocol::TurntableState turntableState() const;
  // Queues the answer of a finished move for the host that asked.
  void answerTurn();
  void sendConfig(std::string_view json);
  void sendControl(std::span<const std::byte> message);
  void dropConnection();
  void pumpSend(std::int64_t nowNs);
  [[nodiscard]] bool idle(std::int64_t nowNs) const;

  hal::Hal hal_;
  DeviceOptions options_;
  std::uint32_t depthUnitNm_;
  std::uint32_t allProjectorsMask_;
  std::uint32_t rangeProjectorsMask_;  // lit for range captures: the owner's choice or all
  std::int64_t leadNs_;
  std::int64_t startNs_;
  std::vector<CameraSlot> cameras_;
  std::vector<hal::CameraFrame> frames_;  // the borrowed frames being decoded, per camera
  std::vector<hal::CameraFrame> next_;    // the capture being taken
  std::size_t decodingCount_ = 0;         // frames_ in use
  std::uint64_t decodingNumber_ = 0;      // their capture's number
  std::unique_ptr<WorkerPool> workers_;
  std::unique_ptr<BackgroundJob> decoding_;  // pipelined only
  std::int64_t framePeriodNs_ = 0;           // of the fastest camera, as configured
  std::int64_t decodeStartNs_ = 0;
  std::atomic<std::int64_t> lastDecodeNs_ = 0;  // written by the decoding thread
  std::uint64_t captureNumber_ = 0;
  DeviceCounters counters_;
  SendQueue queue_;
  std::atomic<bool> streaming_ = false;
  std::atomic<protocol::Compression> compression_ = protocol::Compression::kRvl;
  std::atomic<bool> confidence_ = false;  // the host asked for the confidence planes
  std::atomic<bool> restartDue_ = false;
  std::atomic<bool> updateDue_ = false;

  // Raw capture: the network thread takes a request (kIdle → kRequested), the capture loop
  // serves it (→ kCapturing → kReady), the network thread sends raw_ (→ kSending → kIdle).
  enum class RawState : std::uint8_t { kIdle, kRequested, kCapturing, kReady, kSending };
  std::atomic<RawState> rawState_ = RawState::kIdle;
  std::atomic<std::uint32_t> rawMask_ = 0;
  std::atomic<std::uint64_t> rawConnection_ = 0;  // the host that asked (counters_.connections)
  std::vector<std::byte> raw_;                    // every camera's bands, allocated at create()
  std::size_t rawSize_ = 0;                       // written before kReady, read after

  // Turntable: the network thread takes a request (kIdle → kRequested), the capture loop moves
  // (→ kMoving → kDone), the network thread answers (→ kIdle).
  enum class TurnState : std::uint8_t { kIdle, kRequested, kMoving, kDone };
  std::atomic<std::uint64_t> turnConnection_ = 0;  // the host that asked (counters_.connections)
  std::atomic<std::int64_t> settledNs_ = 0;        // device clock at the end of the last settle
  hal::HalError turnError_{};                      // written before kDone, read after
  std::atomic<std::int32_t> turnSteps_ = 0;
  std::atomic<TurnState> turnState_ = TurnState::kIdle;
  bool turnFailed_ = false;  // written before kDone, read after

  // Network thread only.
  protocol::StreamParser parser_;
  std::vector<std::byte> capabilities_;  // encoded once at create()
  std::vector<std::byte> control_;       // replies waiting to be sent before the next frame
  std::size_t controlSize_ = 0;
  std::span<const std::byte> sending_;  // the message being sent (control or queue slot)
  bool sendingFrame_ = false;
  bool sendingRaw_ = false;
  std::size_t sent_ = 0;
  bool helloSeen_ = false;
  bool restartPending_ = false;  // a set-config was stored; its answer is on the way
  // The upload of this host: flash-begin seen (kReceiving), or a chunk failed (kFailed).
  enum class FlashState : std::uint8_t { kIdle, kReceiving, kFailed };
  FlashState flashState_ = FlashState::kIdle;
  std::uint64_t flashSize_ = 0;
  std::uint64_t flashReceived_ = 0;
  bool hadClient_ = false;
  std::int64_t lastReceivedNs_ = 0;  // the host last sent bytes
  std::int64_t lastSentNs_ = 0;      // the socket last took bytes, or nothing was waiting
  // The counters when this host connected: statisticsForHost() reports what happened since.
  std::uint64_t sentAtConnect_ = 0;
  std::uint64_t droppedAtConnect_ = 0;
  std::uint64_t protocolErrorsAtConnect_ = 0;
};

}  // namespace smx::device
