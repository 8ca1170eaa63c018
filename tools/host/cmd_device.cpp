// `stripemux info` and `stripemux stream`: talk to a device (docs/cli.md, docs/protocol.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.hpp"
#include "decode_debug.hpp"
#include "device_client.hpp"
#include "device_option.hpp"
#include "output_files.hpp"
#include "point_cloud.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/net/tcp_client.hpp"
#include "smx/protocol/wire.hpp"
#include "smx/sim/ply_io.hpp"
#include "smx/sim/png_io.hpp"
#include "terminal_text.hpp"

namespace smx::host {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

constexpr auto kConnectTimeout = std::chrono::milliseconds(3000);

struct DeviceOptions {
  std::string device = "127.0.0.1";
};

struct StreamOptions {
  std::string device = "127.0.0.1";
  fs::path out;
  int frames = 10;
  std::string compression = "rvl";
  double timeoutS = 30;
  bool noPly = false;
  bool confidence = false;
};

std::string describe(const DeviceInfo& info) {
  std::ostringstream s;
  s << "board " << printable(info.board) << ", firmware " << printable(info.firmwareVersion) << " ("
    << printable(info.halBackend) << " HAL), " << info.cameras
    << (info.cameras == 1 ? " camera " : " cameras ") << info.width << "x" << info.height << " at "
    << info.fps << " fps, " << info.projectors << " projectors";
  return s.str();
}

int runInfo(const DeviceOptions& opts, const CliStreams& io) {
  auto client = DeviceClient::connect(opts.device, kConnectTimeout);
  if (!client) {
    io.err << "stripemux info: " << printable(client.error()) << "\n";
    return kExitDeviceOrIo;
  }
  const DeviceInfo& info = client->info();
  io.out << "device " << info.address << "\n"
         << "  board:       " << printable(info.board) << "\n"
         << "  firmware:    " << printable(info.firmwareVersion) << " ("
         << printable(info.halBackend) << " HAL)\n"
         << "  cameras:     " << info.cameras << " x " << info.width << "x" << info.height << " at "
         << info.fps << " fps:";
  for (const auto& camera : info.rig.cameras) {
    io.out << " " << camera.id;
  }
  io.out << "\n  projectors:  " << info.projectors << ":";
  for (const auto& projector : info.rig.projectors) {
    io.out << " " << projector.id;
  }
  io.out << "\n  depth unit:  " << info.depthUnitM << " m\n  compression:";
  for (const auto c : {protocol::Compression::kNone, protocol::Compression::kRvl}) {
    if ((info.compressionsMask >> static_cast<unsigned>(c) & 1U) != 0) {
      io.out << " " << protocol::toString(c);
    }
  }
  io.out << "\n";
  if (client->requestStatistics()) {
    const auto deadline = Clock::now() + kConnectTimeout;
    while (Clock::now() < deadline) {
      auto event = client->next(std::chrono::milliseconds(200));
      if (event && event->kind == DeviceEvent::Kind::kStatistics) {
        const auto& s = event->statistics;
        // Sent and dropped count this connection's frames (none here): not shown.
        io.out << "  up:          " << static_cast<double>(s.uptimeMs) / 1000.0 << " s, "
               << s.framesCaptured << " frames captured, " << s.framesDecoded << " decoded, "
               << s.captureErrors << " capture errors\n";
        break;
      }
    }
  }
  return kExitOk;
}

// Running figures of a stream.
struct StreamTally {
  std::map<int, int> perCamera;
  std::uint64_t frames = 0;
  std::uint64_t wireBytes = 0;
  std::uint64_t rawBytes = 0;
  std::vector<double> latencyMs;  // capture → received (device on loopback)
  std::vector<double> deviceMs;   // capture → queued at the device
  double decodeMsTotal = 0;
  bool clocksAgree = true;

  void add(const ReceivedFrame& frame, bool loopback) {
    ++frames;
    ++perCamera[frame.header.camera];
    wireBytes += frame.wireBytes;
    rawBytes += 2 * frame.depth.size() + frame.confidence.size();
    decodeMsTotal += frame.header.decodeTimeUs / 1000.0;
    const std::int64_t captured = frame.header.captureTimestampNs;
    deviceMs.push_back(static_cast<double>(frame.header.sentTimestampNs - captured) / 1e6);
    if (loopback) {
      const double ms = static_cast<double>(frame.receivedNs - captured) / 1e6;
      // Loopback may still be another clock (a port forwarded into a virtual machine or over
      // ssh): a frame received before it was captured, or a minute after, gives it away.
      clocksAgree = clocksAgree && ms >= 0 && ms < 60'000;
      latencyMs.push_back(ms);
    }
  }
  // Capture → host needs the device's clock to be the host's.
  [[nodiscard]] bool hostLatencyKnown() const { return clocksAgree && !latencyMs.empty(); }
  // Frames of the camera that has the fewest (0 until every camera has sent one).
  [[nodiscard]] int fewestPerCamera(int cameras) const {
    if (perCamera.size() < static_cast<std::size_t>(cameras)) {
      return 0;
    }
    int fewest = std::numeric_limits<int>::max();
    for (const auto& entry : perCamera) {
      fewest = std::min(fewest, entry.second);
    }
    return fewest;
  }
  [[nodiscard]] double bytesPerFrame() const {
    return frames == 0 ? 0 : static_cast<double>(wireBytes) / static_cast<double>(frames);
  }
  [[nodiscard]] double ratio() const {
    return wireBytes == 0 ? 0 : static_cast<double>(rawBytes) / static_cast<double>(wireBytes);
  }
  [[nodiscard]] double decodeMsMean() const {
    return frames == 0 ? 0 : decodeMsTotal / static_cast<double>(frames);
  }
};

double percentile(std::vector<double> v, double q) {
  if (v.empty()) {
    return 0;
  }
  std::ranges::sort(v);
  return v[static_cast<std::size_t>(std::lround(q * static_cast<double>(v.size() - 1)))];
}

double mean(const std::vector<double>& v) {
  double sum = 0;
  for (const double x : v) {
    sum += x;
  }
  return v.empty() ? 0 : sum / static_cast<double>(v.size());
}

Json meanAndP95(const std::vector<double>& v) {
  Json out;
  out["mean"] = mean(v);
  out["p95"] = percentile(v, 0.95);
  return out;
}

// summary.json (docs/cli.md).
Json streamSummary(const StreamTally& tally, const DeviceInfo& info, const StreamOptions& opts,
                   const protocol::Statistics& device, double elapsedS) {
  Json summary;
  summary["device"] = info.address;
  summary["board"] = info.board;
  summary["firmware"] = info.firmwareVersion;
  summary["depth_unit_m"] = info.depthUnitM;
  summary["frames_received"] = tally.frames;
  for (const auto& [camera, count] : tally.perCamera) {
    summary["frames_per_camera"][info.rig.cameras[static_cast<std::size_t>(camera)].id] = count;
  }
  summary["seconds"] = elapsedS;
  summary["fps_per_camera"] = tally.fewestPerCamera(info.cameras) / elapsedS;
  summary["bytes_per_frame"] = tally.bytesPerFrame();
  summary["compression"] = opts.compression;
  summary["confidence"] = opts.confidence;
  summary["compression_ratio"] = tally.ratio();
  summary["mbit_per_s_at_30fps_per_camera"] = tally.bytesPerFrame() * 8 * 30 / 1e6;
  summary["device_capture_to_queued_ms"] = meanAndP95(tally.deviceMs);
  if (tally.hostLatencyKnown()) {
    summary["capture_to_host_ms"] = meanAndP95(tally.latencyMs);
  }
  summary["decode_ms_mean"] = tally.decodeMsMean();
  Json& counters = summary["device_counters"];
  counters["captured"] = device.framesCaptured;
  counters["decoded"] = device.framesDecoded;
  counters["sent"] = device.framesSent;
  counters["dropped"] = device.framesDropped;
  counters["capture_errors"] = device.captureErrors;
  counters["protocol_errors"] = device.protocolErrors;
  return summary;
}

double oneDecimal(double v) {
  return std::round(v * 10) / 10;
}

void printSummary(const StreamTally& tally, const DeviceInfo& info, const StreamOptions& opts,
                  const protocol::Statistics& device, double elapsedS, const std::string& merged,
                  std::ostream& out) {
  const double perFrame = tally.bytesPerFrame();
  out << "received " << tally.frames << " range frames in " << oneDecimal(elapsedS) << " s ("
      << oneDecimal(tally.fewestPerCamera(info.cameras) / elapsedS)
      << " fps per camera); the device sent " << device.framesSent << ", dropped "
      << device.framesDropped << "\n"
      << "  " << std::lround(perFrame / 1024) << " KiB per frame on the wire (" << opts.compression
      << ", " << oneDecimal(tally.ratio()) << ":1), " << oneDecimal(perFrame * 8 * 30 / 1e6)
      << " Mbit/s at 30 fps per camera\n";
  out << "  latency capture -> queued on the device " << oneDecimal(mean(tally.deviceMs))
      << " ms mean, " << oneDecimal(percentile(tally.deviceMs, 0.95)) << " ms p95";
  if (tally.hostLatencyKnown()) {
    out << "; capture -> host " << oneDecimal(mean(tally.latencyMs)) << " ms mean, "
        << oneDecimal(percentile(tally.latencyMs, 0.95)) << " ms p95";
  }
  out << "\n";
  out << "wrote " << opts.out.string() << "/<camera>_<n>.depth.png"
      << (opts.confidence ? ", .confidence.png" : "") << (opts.noPly ? "" : " and .ply") << ", "
      << merged << ", <camera>.preview.png, rig.json and summary.json\n";
}

// Each frame's files appear complete or not at all; a stream that fails keeps the frames it
// received whole.
class FrameWriter {
 public:
  FrameWriter(const StreamOptions& opts, const DeviceInfo& info, OutputFolder& out)
      : opts_(opts), info_(info), out_(out) {}

  // `frame` passed receiveRangeFrame: its camera is one of the rig's (the announcement is the
  // rig's, DeviceClient::connect) and its size the announced one.
  std::expected<void, std::string> write(const ReceivedFrame& frame) {
    const auto cameraIndex = static_cast<std::size_t>(frame.header.camera);
    const algo::Camera& camera = info_.rig.cameras[cameraIndex];
    const auto depth =
        *algo::ConstDepthPlane::packed(frame.depth, frame.header.width, frame.header.height);
    // camera.id passed the rig's id rules (parseRig), and the folder checks the name again.
    const std::string stem = camera.id + "_" + std::to_string(frame.header.frame);
    if (auto ok = writePngGray16(out_, depthPngName(stem), depth); !ok) {
      return ok;
    }
    if (opts_.confidence) {
      if (frame.confidence.empty()) {
        return std::unexpected("the device sent frame " + std::to_string(frame.header.frame) +
                               " of " + camera.id + " without the confidence asked for");
      }
      const auto confidence = *algo::ImageView<const std::uint8_t>::packed(
          frame.confidence, frame.header.width, frame.header.height);
      if (auto ok = writePngGray8(out_, confidencePngName(stem), confidence); !ok) {
        return ok;
      }
    }
    const double unitM = frame.header.depthUnitNm * 1e-9;
    auto points = depthToWorldPoints(camera, depth, unitM);
    if (!opts_.noPly) {
      if (auto ok = writePlyPoints(out_, stem + ".ply", points); !ok) {
        return ok;
      }
    }
    if (auto ok = out_.commit(); !ok) {
      return ok;
    }
    // The latest capture: kept for merged.ply and the previews.
    if (frame.header.frame != latestFrame_) {
      latestFrame_ = frame.header.frame;
      latest_.clear();
    }
    latest_[cameraIndex] = {std::move(points), frame.depth, frame.header};
    return {};
  }

  // merged.ply and <camera>.preview.png of the latest capture (written, not yet committed).
  std::expected<std::string, std::string> finish() {
    std::vector<sim::PlyPoint> merged;
    for (const auto& [camera, kept] : latest_) {
      merged.insert(merged.end(), kept.points.begin(), kept.points.end());
      const auto depth =
          *algo::ConstDepthPlane::packed(kept.depth, kept.header.width, kept.header.height);
      const std::string id = info_.rig.cameras[camera].id;
      if (auto ok = writePngRgb8(out_, id + ".preview.png", renderDepth(depth).view()); !ok) {
        return std::unexpected(ok.error());
      }
    }
    if (auto ok = writePlyPoints(out_, "merged.ply", merged); !ok) {
      return std::unexpected(ok.error());
    }
    return "merged.ply (" + std::to_string(merged.size()) + " points of frame " +
           std::to_string(latestFrame_) + ")";
  }

 private:
  struct Kept {
    std::vector<sim::PlyPoint> points;
    std::vector<std::uint16_t> depth;
    protocol::RangeFrameHeader header;
  };
  const StreamOptions& opts_;
  const DeviceInfo& info_;
  OutputFolder& out_;
  std::uint64_t latestFrame_ = ~std::uint64_t{0};
  std::map<std::size_t, Kept> latest_;
};

int runStream(const StreamOptions& opts, const CliStreams& io) {
  const auto compression =
      opts.compression == "none" ? protocol::Compression::kNone : protocol::Compression::kRvl;
  auto client = DeviceClient::connect(opts.device, kConnectTimeout);
  if (!client) {
    io.err << "stripemux stream: " << printable(client.error()) << "\n";
    return kExitDeviceOrIo;
  }
  const DeviceInfo& info = client->info();
  auto out = OutputFolder::create(opts.out);
  if (!out) {
    io.err << "stripemux stream: " << out.error() << "\n";
    return kExitDeviceOrIo;
  }
  io.out << "connected to " << info.address << ": " << describe(info) << "\n";
  // The rig the frames were decoded with, so that the folder can be fused later
  // (docs/scanning.md): complete before the first frame arrives.
  if (auto ok = out->writeText("rig.json", config::toJson(info.rig)); !ok) {
    io.err << "stripemux stream: " << ok.error() << "\n";
    return kExitDeviceOrIo;
  }
  if (auto ok = out->commit(); !ok) {
    io.err << "stripemux stream: " << ok.error() << "\n";
    return kExitDeviceOrIo;
  }
  if (auto started = client->startStream(compression, opts.confidence); !started) {
    io.err << "stripemux stream: " << printable(started.error()) << "\n";
    return kExitDeviceOrIo;
  }

  FrameWriter writer(opts, info, *out);
  StreamTally tally;
  const bool loopback = isLoopback(info.address);
  const auto start = Clock::now();
  auto lastReport = start;
  std::optional<protocol::Statistics> deviceStats;
  bool stopping = false;
  const auto fail = [&](const std::string& message) {
    io.err << "stripemux stream: " << info.address << ": " << printable(message) << "\n";
    return kExitDeviceOrIo;
  };
  while (!deviceStats) {
    const auto event = client->next(std::chrono::milliseconds(250));
    if (!event) {
      return fail(event.error());
    }
    if (event->kind == DeviceEvent::Kind::kFrame) {
      if (auto ok = writer.write(event->frame); !ok) {
        return fail(ok.error());
      }
      tally.add(event->frame, loopback);
    } else if (event->kind == DeviceEvent::Kind::kStatistics && stopping) {
      deviceStats = event->statistics;
    }
    const auto now = Clock::now();
    const double elapsedS = std::chrono::duration<double>(now - start).count();
    const int fewest = tally.fewestPerCamera(info.cameras);
    if (now - lastReport >= std::chrono::seconds(1)) {
      lastReport = now;
      io.out << "  " << tally.frames << " frames, " << oneDecimal(fewest / elapsedS)
             << " fps per camera, " << std::lround(tally.bytesPerFrame() / 1024) << " KiB/frame\n"
             << std::flush;
    }
    if (!stopping && (fewest >= opts.frames || elapsedS > opts.timeoutS)) {
      if (fewest < opts.frames) {
        io.err << "stripemux stream: only " << fewest << " of " << opts.frames
               << " frames per camera in " << opts.timeoutS << " s; stopping\n";
      }
      if (auto stopped = client->stopStream(); !stopped) {
        return fail(stopped.error());
      }
      stopping = true;
    }
    if (stopping && elapsedS > opts.timeoutS + 10) {
      return fail("no statistics after stop-stream");
    }
  }
  const double elapsedS = std::chrono::duration<double>(Clock::now() - start).count();
  const auto merged = writer.finish();
  if (!merged) {
    return fail(merged.error());
  }

  const protocol::Statistics device = deviceStats.value_or(protocol::Statistics{});  // set here
  if (auto ok = out->writeText("summary.json",
                               streamSummary(tally, info, opts, device, elapsedS)
                                       .dump(2, ' ', false, Json::error_handler_t::replace) +
                                   "\n");
      !ok) {
    return fail(ok.error());
  }
  if (auto ok = out->commit(); !ok) {
    return fail(ok.error());
  }
  printSummary(tally, info, opts, device, elapsedS, *merged, io.out);
  return kExitOk;
}

}  // namespace

void addInfoCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<DeviceOptions>();
  auto* cmd = app.add_subcommand("info", "What a device reports: board, firmware, rig, counters");
  cmd->add_option("--device", opts->device, "HOST[:PORT] of the device (default port 5555)")
      ->required()
      ->check(deviceAddressValidator());
  cmd->callback([opts, &io, &exitCode] { exitCode = runInfo(*opts, io); });
}

void addStreamCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<StreamOptions>();
  auto* cmd = app.add_subcommand(
      "stream", "Receive range images from a device: depth PNGs, PLY point clouds, a summary");
  cmd->add_option("--device", opts->device, "HOST[:PORT] of the device (default port 5555)")
      ->required()
      ->check(deviceAddressValidator());
  cmd->add_option("--out", opts->out, "Output directory")->required();
  cmd->add_option("--frames", opts->frames, "Frames per camera to receive (default 10)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--compression", opts->compression, "rvl (default) or none")
      ->check(CLI::IsMember({"rvl", "none"}));
  cmd->add_option("--timeout", opts->timeoutS, "Give up after this many seconds (default 30)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--no-ply", opts->noPly, "Depth PNGs only, no point cloud per frame");
  cmd->add_flag("--confidence", opts->confidence,
                "Also a confidence PNG (8-bit) per frame, sent by the device beside the depth");
  cmd->callback([opts, &io, &exitCode] { exitCode = runStream(*opts, io); });
}

}  // namespace smx::host
