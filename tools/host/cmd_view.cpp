// stripemux view --device HOST[:PORT] [--port P] [--bind ADDR] [--seconds S] [--summary FILE]
// A live view of the device in a browser (docs/live-view.md): each camera's depth and
// confidence, the point cloud, the device's counters, and controls to start and stop the stream,
// apply a preset, and scan.
#include <atomic>
#include <chrono>
#include <csignal>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>

#include "commands.hpp"
#include "config_change.hpp"
#include "config_presets.hpp"
#include "device_client.hpp"
#include "device_option.hpp"
#include "live_view.hpp"
#include "scan_runner.hpp"
#include "smx/text/printf_text.hpp"
#include "terminal_text.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr auto kReconnectFor = std::chrono::seconds(20);
constexpr auto kViewAnswerTimeout = std::chrono::seconds(5);

struct ViewOptions {
  std::string device;
  view::ServerOptions page;
  double seconds = 0;  // 0: until Ctrl-C
  std::string summary;
  fs::path scans = "scans";
  double timeoutS = 10;
};

std::atomic<bool> interrupted{false};
extern "C" void onViewInterrupt(int /*signal*/) {
  interrupted.store(true);
}

constexpr LiveControls kViewControls{.stream = true, .presets = true, .startScans = true};

// A folder name for a scan started from the page: scans/turntable-20261127-101500.
fs::path scanFolder(const fs::path& scans, const std::string& mode) {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  ::localtime_r(&now, &local);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);
  return scans / (mode + "-" + stamp);
}

class Viewer {
 public:
  Viewer(const ViewOptions& opts, const CliStreams& io, LiveView& live)
      : opts_(opts), io_(io), live_(live) {}

  // Connects (retrying for a while when `retry`), shows the device and starts its stream when
  // the page wants it streaming.
  [[nodiscard]] std::expected<void, std::string> connect(bool retry) {
    const auto deadline = Clock::now() + kReconnectFor;
    while (true) {
      auto client = DeviceClient::connect(opts_.device, kDeviceConnectTimeout);
      if (client) {
        client_ = std::make_unique<DeviceClient>(std::move(*client));
        break;
      }
      if (!retry || Clock::now() > deadline || interrupted.load()) {
        return std::unexpected(client.error());
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
    }
    live_.setDevice(client_->info(), kViewControls);
    if (auto settings = client_->getConfig(kViewAnswerTimeout); settings) {
      live_.setSettings(*settings);
    }
    return streaming_ ? start() : std::expected<void, std::string>{};
  }

  [[nodiscard]] std::expected<void, std::string> run(Clock::time_point end) {
    auto lastStats = Clock::now();
    while (!interrupted.load() && Clock::now() < end) {
      auto event = client_->next(std::chrono::milliseconds(20));
      if (!event) {
        live_.setMessage("connection lost (" + event.error() + "); reconnecting");
        live_.refresh();
        if (auto ok = connect(true); !ok) {
          return ok;
        }
        continue;
      }
      if (event->kind == DeviceEvent::Kind::kFrame && streaming_) {
        live_.frame(event->frame);  // frames still on their way after Stop are not shown
      } else if (event->kind == DeviceEvent::Kind::kStatistics) {
        live_.statistics(event->statistics);
      }
      if (Clock::now() - lastStats >= std::chrono::seconds(1)) {
        lastStats = Clock::now();
        if (auto ok = client_->requestStatistics(); !ok) {
          live_.setMessage("statistics: " + ok.error());
        }
        live_.refresh();
      }
      for (const view::Control& control : live_.takeControls()) {
        if (auto ok = handle(control); !ok) {
          return ok;
        }
      }
    }
    if (streaming_) {
      (void)client_->stopStream();  // the device stops on its own when the connection ends
    }
    return {};
  }

 private:
  [[nodiscard]] std::expected<void, std::string> start() {
    auto ok = client_->startStream(protocol::Compression::kRvl, /*confidence=*/true);
    if (!ok) {  // a device too old for the confidence plane still streams depth
      ok = client_->startStream(protocol::Compression::kRvl, false);
    }
    streaming_ = ok.has_value();
    live_.setStreaming(streaming_);
    live_.refresh();
    return ok;
  }

  [[nodiscard]] std::expected<void, std::string> handle(const view::Control& control) {
    if (control.action == "start" && !streaming_) {
      return start();
    }
    if (control.action == "stop" && streaming_) {
      auto ok = client_->stopStream();
      streaming_ = false;
      live_.setStreaming(false);
      live_.setMessage("stream stopped");
      live_.refresh();
      return ok;
    }
    if (control.action == "preset") {
      return applyPreset(control.value);
    }
    if (control.action == "scan") {
      return scan(control.value);
    }
    if (control.action == "config") {
      return setConfig(control.value);
    }
    return {};  // stop-scan without a scan, start while streaming, stop while stopped
  }

  [[nodiscard]] std::expected<void, std::string> applyPreset(const std::string& name) {
    const auto presets = configPresets();
    const auto preset =
        std::ranges::find_if(presets, [&](const ConfigPreset& p) { return p.name == name; });
    if (preset == presets.end()) {
      live_.setMessage("no preset \"" + printable(name) + "\"");
      live_.refresh();
      return {};
    }
    return restartWith(std::string(preset->json), "applied preset " + name);
  }

  // KEY=VALUE from the page's settings panel, as `stripemux config set` takes it; not the rig,
  // which names a file on this machine.
  [[nodiscard]] std::expected<void, std::string> setConfig(const std::string& assignment) {
    if (assignment.starts_with("rig=")) {
      live_.setMessage("the rig is installed with stripemux config set rig=FILE");
      live_.refresh();
      return {};
    }
    const auto change = changeFromAssignments({assignment});
    if (!change) {
      live_.setMessage(change.error().message);
      live_.refresh();
      return {};
    }
    return restartWith(*change, "set " + printable(assignment));
  }

  // A change the device stores and restarts with; then the view reconnects.
  [[nodiscard]] std::expected<void, std::string> restartWith(const std::string& change,
                                                             const std::string& what) {
    auto changed = client_->setConfig(protocol::SetConfigMode::kChange, change, kViewAnswerTimeout);
    if (!changed) {
      live_.setMessage(what + " refused: " + changed.error());
      live_.refresh();
      return {};
    }
    io_.out << what << "; the device restarts\n" << std::flush;
    live_.setMessage(what + "; the device restarts");
    live_.refresh();
    client_->close();
    return connect(true);
  }

  [[nodiscard]] std::expected<void, std::string> scan(const std::string& mode) {
    if (mode != "turntable" && mode != "handheld") {
      return {};
    }
    const bool wasStreaming = streaming_;
    if (streaming_) {
      (void)client_->stopStream();
    }
    client_->close();
    ScanOptions scan;
    scan.device = opts_.device;
    scan.out = scanFolder(opts_.scans, mode);
    scan.turntable = mode == "turntable";
    scan.handheld = !scan.turntable;
    scan.timeoutS = opts_.timeoutS;
    io_.out << "scan (" << mode << ") into " << scan.out.string() << "\n" << std::flush;
    // The scan's errors go to the terminal and, their last line, to the page.
    std::ostringstream errors;
    const int code = runScan(scan, {io_.out, errors}, &live_);
    io_.err << errors.str();
    std::string why = errors.str();
    while (!why.empty() && why.back() == '\n') {
      why.pop_back();
    }
    why = why.substr(why.find_last_of('\n') + 1);
    live_.setMessage(code == kExitOk ? mode + " scan written to " + scan.out.string()
                                     : mode + " scan failed: " + why);
    live_.setScan(nullptr);
    streaming_ = wasStreaming;
    interrupted.store(false);  // a hand-held scan's Ctrl-C ended the scan, not the view
    return connect(true);
  }

  const ViewOptions& opts_;
  const CliStreams& io_;
  LiveView& live_;
  std::unique_ptr<DeviceClient> client_;  // set by connect()
  bool streaming_ = true;
};

// The figures as JSON, whole or not at all.
std::expected<void, std::string> writeSummary(const ViewOptions& opts, const LiveView& live,
                                              double seconds) {
  const view::PageFigures page = live.pageFigures();
  const HostFigures host = live.hostFigures();
  const nlohmann::json summary{
      {"device", opts.device},
      {"seconds", seconds},
      {"page",
       {{"frames_published", page.framesPublished},
        {"frames_drawn", page.framesDrawn},
        {"drawn_per_s", page.drawnPerSecondRun},
        {"latency_ms",
         {{"mean", page.latencyMeanMs},
          {"p95", page.latencyP95Ms},
          {"samples", page.latencySamples}}}}},
      {"host",
       {{"cpu_percent", host.cpuPercentRun},
        {"page_kib_per_frame", host.pageKibPerFrame},
        {"received_per_s",
         seconds > 0 ? static_cast<double>(page.framesPublished) / seconds : 0.0}}}};
  const fs::path tmp = opts.summary + ".tmp";
  {
    std::ofstream out(tmp);
    out << summary.dump(2) << "\n";
    out.flush();
    if (!out) {
      return std::unexpected("cannot write " + tmp.string());
    }
  }
  std::error_code ec;
  fs::rename(tmp, opts.summary, ec);
  if (ec) {
    return std::unexpected("cannot write " + opts.summary + ": " + ec.message());
  }
  return {};
}

int runView(const ViewOptions& opts, const CliStreams& io) {
  auto live = LiveView::start(opts.page);
  if (!live) {
    io.err << "stripemux view: " << live.error() << "\n";
    return kExitDeviceOrIo;
  }
  Viewer viewer(opts, io, **live);
  if (auto ok = viewer.connect(false); !ok) {
    io.err << "stripemux view: " << printable(ok.error()) << "\n";
    return kExitDeviceOrIo;
  }
  io.out << "live view of " << printable(opts.device) << ": open " << (*live)->url()
         << " in a browser (Ctrl-C to stop)\n"
         << std::flush;
  if (!(*live)->hasThreeJs()) {
    io.out << "  no point cloud: three.js was not found (Debian package libjs-three)\n";
  }
  interrupted.store(false);
  const auto previous = std::signal(SIGINT, onViewInterrupt);
  const auto previousTerm = std::signal(SIGTERM, onViewInterrupt);
  const auto start = Clock::now();
  const auto end =
      opts.seconds > 0 ? start + secondsOption(opts.seconds) : Clock::time_point::max();
  auto ran = viewer.run(end);
  std::signal(SIGINT, previous);
  std::signal(SIGTERM, previousTerm);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const view::PageFigures page = (*live)->pageFigures();
  const HostFigures host = (*live)->hostFigures();
  io.out << text::printfText(
      "%.0f s: %llu frames received, %llu drawn in the page (%.1f fps); received -> drawn %.1f ms "
      "mean, %.1f ms p95; host tool CPU %.0f %% of a core\n",
      seconds, static_cast<unsigned long long>(page.framesPublished),
      static_cast<unsigned long long>(page.framesDrawn), page.drawnPerSecondRun, page.latencyMeanMs,
      page.latencyP95Ms, host.cpuPercentRun);
  if (!opts.summary.empty()) {
    if (auto ok = writeSummary(opts, **live, seconds); !ok) {
      io.err << "stripemux view: " << ok.error() << "\n";
      return kExitDeviceOrIo;
    }
  }
  if (!ran) {
    io.err << "stripemux view: " << printable(ran.error()) << "\n";
    return kExitDeviceOrIo;
  }
  return kExitOk;
}

}  // namespace

void addViewCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<ViewOptions>();
  auto* cmd = app.add_subcommand(
      "view", "See the device live in a browser: depth, confidence, point cloud, counters");
  cmd->add_option("--device", opts->device, "HOST[:PORT] of the device")
      ->required()
      ->check(deviceAddressValidator());
  addPageOptions(*cmd, opts->page, "--");
  cmd->add_option("--seconds", opts->seconds, "Stop after this many seconds (default: Ctrl-C)")
      ->check(CLI::Range(0.1, 1e6));
  cmd->add_option("--summary", opts->summary,
                  "Write the figures (frames drawn, latency, CPU) to this JSON file at the end");
  cmd->add_option("--scans", opts->scans,
                  "Folder of the scans started from the page (default ./scans)");
  cmd->add_option("--timeout", opts->timeoutS,
                  "Seconds a page-started scan waits for each frame (default 10)")
      ->check(CLI::Range(0.1, 3600.0));
  cmd->callback([opts, &io, &exitCode] { exitCode = runView(*opts, io); });
}

}  // namespace smx::host
