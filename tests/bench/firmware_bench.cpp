// The firmware's loop on the simulated board (docs/firmware.md "Figures"): stripemuxd's capture
// loop replaying pre-rendered 640x480 frames (the renderer excluded), 2 projectors, streaming to
// a host over loopback that parses every message and keeps nothing. Counters: captures and range
// frames per second, bytes per frame on the wire, latency from the capture timestamp to the host
// (one clock: same machine), frames dropped at the device. Arguments: cameras, decode threads
// (beyond one per camera they split each camera's frame), whether the capture of the next frame
// overlaps the decoding of the last (pipelined), and the cameras' frame rate: at 1000 fps a
// frame is always ready and decoding alone sets the pace; at 30 fps, as the board's cameras
// run, a capture that does not overlap decoding waits for the next frame.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "replay_board.hpp"
#include "smx/config/board_json.hpp"
#include "smx/device/device.hpp"
#include "smx/hal/board_hal.hpp"
#include "smx/hal/steady_clock.hpp"
#include "smx/net/tcp_client.hpp"
#include "smx/protocol/messages.hpp"
#include "smx/protocol/stream_parser.hpp"

namespace {

using namespace smx;
using namespace std::chrono_literals;

// The device's clock: capture timestamps and this host share it on one machine.
std::int64_t nowNs() {
  return hal::SteadyClock().nowNs();
}

// Receives and parses everything, recording what a host would measure.
class Host {
 public:
  explicit Host(std::uint16_t port) {
    auto socket =
        net::TcpClient::connect({"127.0.0.1", port}, 2000ms).value();  // throws on failure
    std::array<std::byte, 256> out{};
    (void)socket.sendAll(protocol::encode(protocol::Hello{"bench"}, out).value(), 1000ms);
    (void)socket.sendAll(
        protocol::encode(protocol::StartStream{protocol::Compression::kRvl}, out).value(), 1000ms);
    socket_.emplace(std::move(socket));
    thread_ = std::jthread([this] { run(); });
  }
  ~Host() { stop_ = true; }
  Host(const Host&) = delete;
  Host& operator=(const Host&) = delete;

  [[nodiscard]] std::uint64_t frames() const { return frames_; }
  [[nodiscard]] std::uint64_t bytes() const { return bytes_; }
  [[nodiscard]] std::vector<double> latenciesMs() {
    const std::lock_guard lock(mutex_);
    return latenciesMs_;
  }

 private:
  void run() {
    protocol::StreamParser parser(protocol::kMaxPayloadBytes);
    while (!stop_) {
      const auto got = socket_->receiveSome(parser.writable(), 50ms);
      if (!got) {
        return;
      }
      parser.commit(*got);
      for (auto next = parser.next(); next && next->has_value(); next = parser.next()) {
        if ((*next)->type != protocol::MessageType::kRangeFrame) {
          continue;
        }
        const auto frame = protocol::decodeRangeFrame((*next)->payload);
        if (!frame) {
          continue;
        }
        ++frames_;
        bytes_ += protocol::kHeaderBytes + (*next)->payload.size();
        const std::lock_guard lock(mutex_);
        latenciesMs_.push_back(static_cast<double>(nowNs() - frame->header.captureTimestampNs) /
                               1e6);
      }
    }
  }

  std::optional<net::TcpClient> socket_;
  std::atomic<bool> stop_ = false;
  std::atomic<std::uint64_t> frames_ = 0;
  std::atomic<std::uint64_t> bytes_ = 0;
  std::mutex mutex_;
  std::vector<double> latenciesMs_;
  std::jthread thread_;
};

void BM_FirmwareLoop(benchmark::State& state) {
  const auto cameras = static_cast<std::size_t>(state.range(0));
  config::Board board = test::replayBoard(static_cast<int>(cameras), 5);
  for (auto& camera : board.config.cameras) {
    camera.format.fps = static_cast<int>(state.range(3));
  }
  auto boardHal = hal::createBoardHal(board.config, board.rig).value();
  device::DeviceOptions options;
  options.decodeThreads = static_cast<int>(state.range(1));
  options.pipelined = state.range(2) != 0;
  auto device = device::Device::create(board, boardHal->hal(), options).value();
  std::atomic<bool> stopNetwork = false;
  std::jthread network([&] { device->runNetwork(stopNetwork); });
  Host host(boardHal->hal().link.port());
  while (!device->streaming()) {
    std::this_thread::sleep_for(1ms);
  }

  for (auto _ : state) {
    if (!device->captureOnce()) {
      state.SkipWithError("capture failed");
      break;
    }
  }
  device->finishCapture();
  // Let the host catch up with what was queued.
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (host.frames() + device->framesDropped() < device->counters().framesQueued &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(5ms);
  }
  stopNetwork = true;

  auto latencies = host.latenciesMs();
  std::ranges::sort(latencies);
  const auto at = [&](double q) {
    return latencies.empty()
               ? 0.0
               : latencies[static_cast<std::size_t>(q * static_cast<double>(latencies.size() - 1))];
  };
  double sum = 0;
  for (const double l : latencies) {
    sum += l;
  }
  state.counters["captures/s"] =
      benchmark::Counter(1, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(cameras),
                                                  benchmark::Counter::kIsIterationInvariantRate);
  state.counters["bytes_per_frame"] =
      host.frames() == 0 ? 0
                         : static_cast<double>(host.bytes()) / static_cast<double>(host.frames());
  state.counters["latency_ms_mean"] =
      latencies.empty() ? 0 : sum / static_cast<double>(latencies.size());
  state.counters["latency_ms_p95"] = at(0.95);
  state.counters["dropped"] = static_cast<double>(device->framesDropped());
  state.counters["received"] = static_cast<double>(host.frames());
}

BENCHMARK(BM_FirmwareLoop)
    ->ArgNames({"cameras", "threads", "pipelined", "fps"})
    ->Args({1, 1, 0, 1000})
    ->Args({1, 2, 0, 1000})
    ->Args({1, 1, 1, 1000})
    ->Args({1, 2, 1, 1000})
    ->Args({1, 1, 0, 30})
    ->Args({1, 1, 1, 30})
    ->Args({1, 2, 0, 30})
    ->Args({1, 2, 1, 30})
    ->Args({2, 1, 0, 1000})
    ->Args({2, 2, 0, 1000})
    ->Args({2, 2, 1, 30})
    ->Iterations(30)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
