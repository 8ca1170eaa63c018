// The firmware end to end on the simulated board over loopback (label "sim"): the capture and
// network loops of stripemuxd, a host on a real TCP connection, faults injected into the
// simulated cameras. Frames are replayed from renders made once, so the pipeline sees the same
// images `stripemux decode` is given.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <memory>
#include <sstream>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "cli.hpp"
#include "device_client.hpp"
#include "replay_board.hpp"
#include "sim_device.hpp"
#include "smx/config/board_json.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/device/device.hpp"
#include "smx/hal/board_hal.hpp"
#include "smx/net/tcp_client.hpp"
#include "smx/protocol/messages.hpp"
#include "smx/scan/views_folder.hpp"
#include "smx/sim/png_io.hpp"
#include "smx/sim/sim_board.hpp"
#include "source_dir.hpp"

namespace smx {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kSource = smx::test::sourceDir();
constexpr int kReplayFrames = 3;

int cli(const std::vector<std::string>& args) {
  std::ostringstream out;
  std::ostringstream err;
  const int code = host::runCli(args, {out, err});
  EXPECT_EQ(code, 0) << err.str();
  return code;
}

// The sim board replaying its rig's renders, with a small send buffer so that a slow host is
// felt after a few frames.
config::Board simBoard(int cameras) {
  config::Board board = test::replayBoard(cameras, kReplayFrames);
  board.config.network.sendBufferBytes = 64 * 1024;
  return board;
}

// A device on the simulated board with its network loop running.
class RunningDevice : public test::SimDevice {
 public:
  explicit RunningDevice(int cameras, const device::DeviceOptions& options = {})
      : test::SimDevice(simBoard(cameras), {.device = options}) {}
};

device::DeviceOptions idleTimeout(std::int64_t ns) {
  device::DeviceOptions options;
  options.idleTimeoutNs = ns;
  return options;
}

// A host that says hello, starts the stream and then only reads into one fixed buffer (or, while
// `paused`, not at all): it allocates nothing after connect.
class RawHost {
 public:
  explicit RawHost(const std::string& address) {
    auto parsed = net::parseDeviceAddress(address, 0).value();
    auto socket = net::TcpClient::connect(parsed, 2000ms);
    EXPECT_TRUE(socket.has_value());
    socket_.emplace(std::move(*socket));
  }
  void send(const protocol::ProtocolResult<std::span<const std::byte>>& message) {
    ASSERT_TRUE(message.has_value());
    ASSERT_TRUE(socket_->sendAll(*message, 2000ms).has_value());
  }
  void helloAndStart(bool confidence = false) {
    std::array<std::byte, 256> out{};
    send(protocol::encode(protocol::Hello{"raw host"}, out));
    send(protocol::encode(
        protocol::StartStream{.compression = protocol::Compression::kRvl, .confidence = confidence},
        out));
  }
  void startDraining() {
    reader_ = std::jthread([this] {
      while (!stop_) {
        if (paused_) {
          std::this_thread::sleep_for(5ms);
          continue;
        }
        const auto got = socket_->receiveSome(buffer_, 50ms);
        if (!got) {
          return;
        }
        bytes_ += *got;
      }
    });
  }
  void pause(bool paused) { paused_ = paused; }
  [[nodiscard]] std::uint64_t bytes() const { return bytes_; }
  // Waits at most `wait` for the device to close the connection (what was sent is read).
  [[nodiscard]] bool closedByDevice(std::chrono::milliseconds wait) {
    std::array<std::byte, 1 << 16> sink{};
    const auto deadline = std::chrono::steady_clock::now() + wait;
    while (std::chrono::steady_clock::now() < deadline) {
      if (!socket_->receiveSome(sink, 50ms)) {
        return true;
      }
    }
    return false;
  }
  ~RawHost() { stop_ = true; }
  RawHost(const RawHost&) = delete;
  RawHost& operator=(const RawHost&) = delete;

 private:
  std::optional<net::TcpClient> socket_;
  std::array<std::byte, 1 << 16> buffer_{};
  std::atomic<bool> stop_ = false;
  std::atomic<bool> paused_ = false;
  std::atomic<std::uint64_t> bytes_ = 0;
  std::jthread reader_;
};

class FirmwareSim : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    for (const int cameras : {1, 2}) {
      (void)test::replayFrames(cameras, kReplayFrames);  // rendered once, before any timing
    }
  }
};

// Steady-state captures streamed to a host (with or without the confidence planes) allocate
// nothing.
void expectStreamedFramesAllocateNothing(bool confidence,
                                         const device::DeviceOptions& options = {}) {
  RunningDevice running(1, options);
  RawHost host(running.address());
  host.helloAndStart(confidence);
  host.startDraining();
  // Warm up: the host is accepted and streaming, every buffer has been touched.
  while (!running.device().streaming()) {
    std::this_thread::sleep_for(1ms);
  }
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(running.device().captureOnce().has_value());
  }
  running.device().finishCapture();  // pipelined, the last one may still be decoding
  const auto& counters = running.device().counters();
  const std::uint64_t decodedBefore = counters.framesDecoded;
  const std::uint64_t queuedBefore = counters.framesQueued;

  const test::AllocationCounter allocations;
  int failed = 0;
  constexpr int frames = test::kSteadyStateFrames;
  for (int i = 0; i < frames; ++i) {
    failed += running.device().captureOnce().has_value() ? 0 : 1;
  }
  running.device().finishCapture();
  const std::uint64_t heapCalls = allocations.allocations();

  EXPECT_EQ(heapCalls, 0U) << "the capture and network loops allocated during " << frames
                           << " frames";
  EXPECT_EQ(failed, 0);
  EXPECT_EQ(counters.framesDecoded - decodedBefore, std::uint64_t{frames});
  EXPECT_EQ(counters.framesQueued - queuedBefore, std::uint64_t{frames});
  // and they went out to the host meanwhile
  EXPECT_GT(counters.framesSent, std::uint64_t{frames / 2});
  EXPECT_GT(host.bytes(), std::uint64_t{frames / 2} * 50'000U);
}

TEST_F(FirmwareSim, StreamedFramesAllocateNothing) {
  expectStreamedFramesAllocateNothing(false);
}

TEST_F(FirmwareSim, StreamedFramesWithConfidenceAllocateNothing) {
  expectStreamedFramesAllocateNothing(true);
}

// Two threads on one camera's frame (its projectors on lanes), capture overlapping decoding.
device::DeviceOptions threadsAndPipelined(int threads) {
  device::DeviceOptions options;
  options.decodeThreads = threads;
  options.pipelined = true;
  return options;
}

TEST_F(FirmwareSim, PipelinedFramesOnTwoThreadsAllocateNothing) {
  expectStreamedFramesAllocateNothing(false, threadsAndPipelined(2));
}

// Streams 8 frames of two cameras (with the confidence planes when asked), checks that every
// frame the device sent arrived, and compares each with `stripemux decode` of the same image.
void expectStreamEqualsOfflineDecode(bool confidence, const device::DeviceOptions& options = {}) {
  RunningDevice running(2, options);
  running.startCapture();
  auto client = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_TRUE(client.has_value()) << client.error();
  EXPECT_EQ(client->info().board, "sim");
  EXPECT_EQ(client->info().cameras, 2);
  ASSERT_TRUE(client->startStream(protocol::Compression::kRvl, confidence).has_value());

  std::vector<host::ReceivedFrame> frames;
  std::optional<protocol::Statistics> stats;
  bool stopped = false;
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (!stats && std::chrono::steady_clock::now() < deadline) {
    auto event = client->next(200ms);
    ASSERT_TRUE(event.has_value()) << event.error();
    if (event->kind == host::DeviceEvent::Kind::kFrame) {
      frames.push_back(std::move(event->frame));
    } else if (event->kind == host::DeviceEvent::Kind::kStatistics && stopped) {
      stats = event->statistics;
    }
    if (!stopped && frames.size() >= 8) {
      ASSERT_TRUE(client->stopStream().has_value());
      stopped = true;
    }
  }
  ASSERT_TRUE(stats.has_value()) << "no statistics after stop-stream";
  EXPECT_EQ(stats->framesSent, frames.size()) << "frames sent by the device != received";
  EXPECT_EQ(stats->protocolErrors, 0U);
  EXPECT_EQ(client->protocolErrors(), 0U);

  // `stripemux decode` on each replayed image, once.
  const fs::path offline =
      fs::temp_directory_path() /
      (confidence ? "smx_firmware_sim_test_decode_confidence" : "smx_firmware_sim_test_decode");
  for (int i = 0; i < kReplayFrames; ++i) {
    const std::string n = std::to_string(i);
    cli({"decode", "--rig", (kSource / "boards/sim/rig_2proj_2cam.json").string(), "--image",
         "cam0=" + (test::replayFrames(2, kReplayFrames) / ("cam0_" + n + ".png")).string(),
         "--image",
         "cam1=" + (test::replayFrames(2, kReplayFrames) / ("cam1_" + n + ".png")).string(),
         "--out", (offline / n).string()});
  }
  for (const auto& frame : frames) {
    // The simulated camera replays image k for its k-th frame; no capture failed here, so the
    // device's frame number is k.
    const std::string id = frame.header.camera == 0 ? "cam0" : "cam1";
    const fs::path decoded = offline / std::to_string(frame.header.frame % kReplayFrames);
    const auto expected = sim::readPngGray16(decoded / (id + ".depth.png"));
    ASSERT_TRUE(expected.has_value());
    EXPECT_EQ(frame.depth, expected->pixels)
        << id << " frame " << frame.header.frame << " differs from stripemux decode";
    if (!confidence) {
      EXPECT_TRUE(frame.confidence.empty());
      continue;
    }
    // 8-bit grey read as RGB: each channel is the confidence.
    const auto expectedConfidence = sim::readPngRgb8(decoded / (id + ".confidence.png"));
    ASSERT_TRUE(expectedConfidence.has_value());
    ASSERT_EQ(frame.confidence.size(), expectedConfidence->pixels.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < frame.confidence.size(); ++i) {
      differing += frame.confidence[i] != expectedConfidence->pixels[i].r ? 1U : 0U;
    }
    EXPECT_EQ(differing, 0U) << id << " frame " << frame.header.frame
                             << ": confidence differs from stripemux decode";
  }
}

TEST_F(FirmwareSim, StreamedDepthEqualsOfflineDecodeAndEveryFrameSentArrives) {
  expectStreamEqualsOfflineDecode(false);
}

TEST_F(FirmwareSim, StreamedConfidenceEqualsOfflineDecodeAndEveryFrameSentArrives) {
  expectStreamEqualsOfflineDecode(true);
}

// Four threads: the two cameras at once, each frame split over two; capture overlaps decoding.
TEST_F(FirmwareSim, PipelinedOnFourThreadsTheStreamStillEqualsOfflineDecode) {
  expectStreamEqualsOfflineDecode(true, threadsAndPipelined(4));
}

// `stripemux stream --confidence` writes a confidence PNG beside each depth PNG, 0 exactly where
// the depth is 0.
TEST_F(FirmwareSim, StreamCommandWritesTheConfidenceBesideEachDepth) {
  RunningDevice running(1);
  running.startCapture();
  const fs::path out = fs::temp_directory_path() / "smx_firmware_sim_test_stream_confidence";
  fs::remove_all(out);
  cli({"stream", "--device", running.address(), "--out", out.string(), "--frames", "2",
       "--confidence", "--no-ply"});
  int pairs = 0;
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    if (!name.ends_with(".depth.png")) {
      continue;
    }
    const std::string stem = name.substr(0, name.size() - std::string(".depth.png").size());
    const auto depth = sim::readPngGray16(entry.path());
    const auto confidence = sim::readPngRgb8(out / (stem + ".confidence.png"));
    ASSERT_TRUE(depth.has_value()) << depth.error();
    ASSERT_TRUE(confidence.has_value()) << confidence.error();
    ASSERT_EQ(confidence->pixels.size(), depth->pixels.size()) << stem;
    std::size_t mismatched = 0;
    for (std::size_t i = 0; i < depth->pixels.size(); ++i) {
      mismatched += (confidence->pixels[i].r == 0) != (depth->pixels[i] == 0) ? 1U : 0U;
    }
    EXPECT_EQ(mismatched, 0U) << stem;
    ++pairs;
  }
  EXPECT_GE(pairs, 2);
  // The folder is a views folder `stripemux fuse` reads: the rig beside the frames.
  const auto folder = scan::readViewsFolder(out);
  ASSERT_TRUE(folder.has_value()) << folder.error();
  EXPECT_EQ(folder->rig.cameras.size(), 1U);
  EXPECT_GE(folder->views.size(), 2U);
}

TEST_F(FirmwareSim, AHostCanLeaveAndAnotherConnect) {
  RunningDevice running(1);
  running.startCapture();
  for (int round = 0; round < 2; ++round) {
    auto client = host::DeviceClient::connect(running.address(), 3000ms);
    ASSERT_TRUE(client.has_value()) << client.error();
    ASSERT_TRUE(client->startStream(protocol::Compression::kRvl).has_value());
    int received = 0;
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    while (received < 2 && std::chrono::steady_clock::now() < deadline) {
      auto event = client->next(200ms);
      ASSERT_TRUE(event.has_value()) << event.error();
      received += event->kind == host::DeviceEvent::Kind::kFrame ? 1 : 0;
    }
    EXPECT_EQ(received, 2) << "round " << round;
    client->close();  // leaves mid-stream, without stop
  }
  EXPECT_EQ(running.device().counters().connections, 2U);
}

TEST_F(FirmwareSim, ASlowHostMakesTheDeviceDropFramesButNotStopCapturing) {
  RunningDevice running(1);
  RawHost host(running.address());
  host.helloAndStart();
  host.pause(true);
  host.startDraining();
  while (!running.device().streaming()) {
    std::this_thread::sleep_for(1ms);
  }
  // The host reads nothing while the device captures 25 frames: each capture still completes.
  constexpr int kCaptures = 25;
  for (int i = 0; i < kCaptures; ++i) {
    ASSERT_TRUE(running.device().captureOnce().has_value()) << "capture " << i;
  }
  const auto& counters = running.device().counters();
  EXPECT_EQ(counters.framesDecoded, std::uint64_t{kCaptures});
  EXPECT_EQ(counters.captureErrors, 0U);
  // What is not dropped fits in the queue (4 slots) and the socket buffers (a few frames).
  EXPECT_GE(running.device().framesDropped(), std::uint64_t{kCaptures - 12});
  // Once the host reads again, frames flow.
  const std::uint64_t sentBefore = counters.framesSent;
  host.pause(false);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(running.device().captureOnce().has_value());
  }
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (counters.framesSent <= sentBefore && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_GT(counters.framesSent, sentBefore);
}

TEST_F(FirmwareSim, TriggerLinesAreActiveDuringEveryExposure) {
  RunningDevice running(2);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(running.device().captureOnce().has_value());
  }
  const auto edges = running.control().triggerEdges();
  ASSERT_EQ(edges.size(), 6U);  // on and off per capture
  for (std::size_t i = 0; i < edges.size(); ++i) {
    EXPECT_EQ(edges[i].activeMask, i % 2 == 0 ? 0b11U : 0U) << "edge " << i;
  }
  EXPECT_EQ(running.control().lastExposureMask(0), 0b11U);
  EXPECT_EQ(running.control().lastExposureMask(1), 0b11U);
}

// The owner's projector subset (docs/config.md): range captures light only those lines, and a
// replaying board, whose images cannot change, refuses dimming and exposure.
TEST_F(FirmwareSim, RangeCapturesLightOnlyTheChosenProjectors) {
  config::Board board = simBoard(2);
  board.config.trigger.rangeMask = 0b10U;
  auto made = hal::createBoardHal(board.config, board.rig);
  ASSERT_TRUE(made.has_value()) << made.error();
  auto device = device::Device::create(board, (*made)->hal(), {});
  ASSERT_TRUE(device.has_value()) << device.error();
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE((*device)->captureOnce().has_value());
  }
  const auto edges = sim::simBoardControl(**made)->triggerEdges();
  ASSERT_EQ(edges.size(), 4U);
  for (std::size_t i = 0; i < edges.size(); ++i) {
    EXPECT_EQ(edges[i].activeMask, i % 2 == 0 ? 0b10U : 0U) << "edge " << i;
  }
  device->reset();

  board.config.trigger.powerPercent = 50;
  auto dimmed = device::Device::create(board, (*made)->hal(), {});
  ASSERT_FALSE(dimmed.has_value());
  EXPECT_NE(dimmed.error().find("projector_power"), std::string::npos) << dimmed.error();
  board.config.trigger.powerPercent = 100;
  for (smx::hal::Camera* camera : (*made)->hal().cameras) {
    (void)camera->stop();
  }
  board.config.cameras[0].controls.exposureUs = 5000;
  auto exposed = device::Device::create(board, (*made)->hal(), {});
  ASSERT_FALSE(exposed.has_value());
  EXPECT_NE(exposed.error().find("exposure"), std::string::npos) << exposed.error();
}

TEST_F(FirmwareSim, CameraFaultsAreCountedAndCaptureRecovers) {
  RunningDevice running(1);
  running.control().injectTimeouts(0, 2);
  EXPECT_EQ(running.device().captureOnce().error().code, hal::HalErrc::kTimeout);
  EXPECT_EQ(running.device().captureOnce().error().code, hal::HalErrc::kTimeout);
  EXPECT_TRUE(running.device().captureOnce().has_value());

  running.control().disconnect(0);
  EXPECT_EQ(running.device().captureOnce().error().code, hal::HalErrc::kDisconnected);
  EXPECT_FALSE(running.hal().cameras[0]->recover().has_value());
  running.control().reconnect(0);
  EXPECT_TRUE(running.hal().cameras[0]->recover().has_value());
  EXPECT_TRUE(running.device().captureOnce().has_value());
  EXPECT_EQ(running.device().counters().captureErrors, 3U);
  EXPECT_EQ(running.device().counters().framesDecoded, 2U);
}

TEST_F(FirmwareSim, GarbageFromTheHostIsCountedAndTheConnectionStaysUsable) {
  RunningDevice running(1);
  auto parsed = net::parseDeviceAddress(running.address(), 0).value();
  auto socket = net::TcpClient::connect(parsed, 2000ms);
  ASSERT_TRUE(socket.has_value());
  std::array<std::byte, 512> out{};
  // Garbage, a message of protocol version 9, then a good hello.
  const std::array<std::byte, 5> garbage{std::byte{'x'}, std::byte{1}, std::byte{'S'}, std::byte{2},
                                         std::byte{3}};
  ASSERT_TRUE(socket->sendAll(garbage, 1000ms).has_value());
  auto hello = protocol::encode(protocol::Hello{"v9"}, out).value();
  std::vector<std::byte> v9(hello.begin(), hello.end());
  v9[4] = std::byte{9};
  ASSERT_TRUE(socket->sendAll(v9, 1000ms).has_value());
  ASSERT_TRUE(socket->sendAll(protocol::encode(protocol::Hello{"ok"}, out).value(), 1000ms));

  protocol::StreamParser parser(1 << 20);
  std::vector<protocol::MessageType> replies;
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (replies.size() < 2 && std::chrono::steady_clock::now() < deadline) {
    const auto got = socket->receiveSome(parser.writable(), 100ms);
    ASSERT_TRUE(got.has_value()) << got.error();
    parser.commit(*got);
    for (auto next = parser.next(); next && next->has_value(); next = parser.next()) {
      replies.push_back((*next)->type);
    }
  }
  ASSERT_EQ(replies.size(), 2U);
  EXPECT_EQ(replies[0], protocol::MessageType::kError);  // "this device speaks version 1"
  EXPECT_EQ(replies[1], protocol::MessageType::kCapabilities);
  EXPECT_GE(running.device().counters().protocolErrors, 2U);  // the garbage and the v9 message
}

// Given a host streaming from the device, when a second host connects, then the second is told
// the device is busy and by whom, and the first goes on receiving frames.
TEST_F(FirmwareSim, ASecondHostIsToldTheDeviceIsBusyAndTheFirstKeepsStreaming) {
  RunningDevice running(1);
  running.startCapture();
  auto first = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_TRUE(first.has_value()) << first.error();
  ASSERT_TRUE(first->startStream(protocol::Compression::kRvl).has_value());
  const auto receive = [&](int frames) {
    int received = 0;
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    while (received < frames && std::chrono::steady_clock::now() < deadline) {
      auto event = first->next(200ms);
      EXPECT_TRUE(event.has_value()) << event.error();
      if (!event) {
        return received;
      }
      received += event->kind == host::DeviceEvent::Kind::kFrame ? 1 : 0;
    }
    return received;
  };
  ASSERT_EQ(receive(1), 1);

  const auto second = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_FALSE(second.has_value());
  EXPECT_NE(second.error().find("the device is busy"), std::string::npos) << second.error();
  EXPECT_NE(second.error().find("held by 127.0.0.1:"), std::string::npos) << second.error();

  EXPECT_EQ(receive(2), 2) << "the first host lost its stream";
  EXPECT_EQ(running.device().counters().connections, 1U);
}

// Given a device with a short idle timeout, when a host says hello and then nothing, then the
// device disconnects it after the timeout, and another host is served.
TEST_F(FirmwareSim, AHostSilentWhileNotStreamingIsDroppedAfterTheIdleTimeout) {
  RunningDevice running(1, idleTimeout(300'000'000));
  // Before connect: the device's idle time starts at the hello, which connect() sends.
  const auto start = std::chrono::steady_clock::now();
  auto silent = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_TRUE(silent.has_value()) << silent.error();
  std::optional<std::string> closed;
  while (!closed && std::chrono::steady_clock::now() - start < 5s) {
    if (auto event = silent->next(100ms); !event) {
      closed = event.error();
    }
  }
  ASSERT_TRUE(closed.has_value()) << "a silent host still holds the device after 5 s";
  EXPECT_GE(std::chrono::steady_clock::now() - start, 300ms);
  EXPECT_EQ(running.device().counters().idleDisconnects, 1U);

  auto next = host::DeviceClient::connect(running.address(), 3000ms);
  EXPECT_TRUE(next.has_value()) << next.error();
}

// Given a device with a short idle timeout, when a streaming host stops reading, then the
// device disconnects it; a streaming host that reads but sends nothing is kept.
TEST_F(FirmwareSim, AStreamingHostIsKeptWhileItReadsAndDroppedWhenItStops) {
  RunningDevice running(1, idleTimeout(1'000'000'000));
  running.startCapture();
  RawHost host(running.address());
  host.helloAndStart();
  host.startDraining();
  // Three timeouts of sending nothing while reading: still connected and receiving.
  std::this_thread::sleep_for(3s);
  const std::uint64_t bytesBefore = host.bytes();
  EXPECT_GT(bytesBefore, 0U);
  EXPECT_EQ(running.device().counters().idleDisconnects, 0U);

  // The device stalls once the host's receive buffer and its own send buffer are full, which
  // takes as many frames as they hold: seconds at the optimised build's frame rate, tens of
  // seconds under the sanitisers on a loaded machine. The bound is for a hung test only.
  host.pause(true);
  const auto deadline = std::chrono::steady_clock::now() + 90s;
  while (running.device().counters().idleDisconnects == 0 &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(running.device().counters().idleDisconnects, 1U)
      << "a host that reads nothing still holds the device after 90 s";
  host.pause(false);
  EXPECT_TRUE(host.closedByDevice(5s));
}

// Given a first host that made the device drop frames and sent a bad message, when a second
// host streams three captures and stops, then its statistics count its own connection: the
// three frames it received, nothing dropped, no protocol error.
TEST_F(FirmwareSim, StatisticsCountTheHostsOwnConnection) {
  RunningDevice running(1);
  {
    RawHost first(running.address());
    first.helloAndStart();
    std::array<std::byte, 64> out{};
    first.send(protocol::encodeEmpty(protocol::MessageType::kCapabilities, out));  // not for it
    while (!running.device().streaming()) {
      std::this_thread::sleep_for(1ms);
    }
    for (int i = 0; i < 25; ++i) {  // the host reads nothing: frames are dropped
      ASSERT_TRUE(running.device().captureOnce().has_value());
    }
  }
  ASSERT_GT(running.device().framesDropped(), 0U);
  ASSERT_GT(running.device().counters().protocolErrors, 0U);

  auto second = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_TRUE(second.has_value()) << second.error();
  ASSERT_TRUE(second->startStream(protocol::Compression::kRvl).has_value());
  while (!running.device().streaming()) {
    std::this_thread::sleep_for(1ms);
  }
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(running.device().captureOnce().has_value());
  }
  int received = 0;
  std::optional<protocol::Statistics> stats;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!stats && std::chrono::steady_clock::now() < deadline) {
    auto event = second->next(200ms);
    ASSERT_TRUE(event.has_value()) << event.error();
    if (event->kind == host::DeviceEvent::Kind::kFrame && ++received == 3) {
      ASSERT_TRUE(second->stopStream().has_value());
    } else if (event->kind == host::DeviceEvent::Kind::kStatistics) {
      stats = event->statistics;
    }
  }
  ASSERT_TRUE(stats.has_value());
  EXPECT_EQ(stats->framesSent, 3U);
  EXPECT_EQ(stats->framesDropped, 0U);
  EXPECT_EQ(stats->protocolErrors, 0U);
  EXPECT_EQ(stats->framesDecoded, 28U);  // the device's own work counts since start-up
}

}  // namespace
}  // namespace smx
