#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <expected>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "device_client.hpp"
#include "smx/scan/points.hpp"
#include "smx/scan/range_view.hpp"
#include "smx/view/live_feed.hpp"
#include "smx/view/sides_seen.hpp"
#include "smx/view/view_server.hpp"

// The live view of `stripemux view` and `stripemux scan --view` (docs/live-view.md): what the
// command's loop received, handed to the page server as the page wants it. Only the loop talks
// to the device; the page's controls come back through takeControl().
namespace smx::host {

// Which page controls a command offers (the others are shown disabled).
struct LiveControls {
  bool stream = false;      // start / stop
  bool presets = false;     // apply a preset
  bool startScans = false;  // turntable / hand-held scan
  bool stopScan = false;    // end a hand-held scan
};

// The host's side of the figures: frames received, the host tool's CPU.
struct HostFigures {
  double receivedPerSecond = 0.0;
  double captureToHostMs = 0.0;  // mean of the last frames; 0 when the clocks differ
  double pageKibPerFrame = 0.0;  // depth messages to the page
  double cpuPercent = 0.0;       // of one core, over the last second or so
  double cpuPercentRun = 0.0;    // over the whole run
};

// --port/--bind of the page server (with a prefix: --view-port, --view-bind), each needing
// `needs` when given.
void addPageOptions(CLI::App& cmd, view::ServerOptions& options, const std::string& prefix,
                    CLI::Option* needs = nullptr);

class LiveView {
 public:
  [[nodiscard]] static std::expected<std::unique_ptr<LiveView>, std::string> start(
      const view::ServerOptions& options);

  [[nodiscard]] std::string url() const { return server_->url(); }
  [[nodiscard]] bool hasThreeJs() const { return server_->hasThreeJs(); }

  // A (re)connected device: the page's session (device, cameras and their rays, controls).
  void setDevice(const DeviceInfo& info, const LiveControls& controls);
  void frame(const ReceivedFrame& frame);
  // A camera's depth without a received frame (a scan's view): the latency starts now.
  void depth(std::size_t camera, int width, int height, const std::vector<std::uint16_t>& depth,
             std::uint64_t deviceFrame);
  // Every camera of a scan's view, as depth().
  void view(const scan::RangeView& view);
  void statistics(const protocol::Statistics& statistics) { statistics_ = statistics; }
  void setStreaming(bool streaming) { streaming_ = streaming; }
  // The device's settings (a stripemux-config/1 document), shown without the rig.
  void setSettings(const std::string& document);
  void setMessage(std::string message) { message_ = std::move(message); }
  // The scan's figures (null: no scan) and its model so far (at most kModelPoints shown).
  void setScan(nlohmann::json scan) { scan_ = std::move(scan); }
  void model(const scan::Cloud& cloud);
  // Recomputes the host's figures and hands the status to the pages; call about once a second.
  void refresh();
  [[nodiscard]] std::vector<view::Control> takeControls() { return feed_.takeControls(); }
  [[nodiscard]] view::PageFigures pageFigures() const { return feed_.figures(); }
  [[nodiscard]] HostFigures hostFigures() const { return host_; }

  static constexpr std::size_t kModelPoints = 150'000;

 private:
  LiveView() = default;
  void received(std::int64_t receivedNs, std::size_t messageBytes);
  [[nodiscard]] algo::ImageView<const std::uint8_t> pageConfidence(const ReceivedFrame& frame);

  static constexpr int kConfidenceStep = 2;

  view::LiveFeed feed_;
  std::unique_ptr<view::ViewServer> server_;
  DeviceInfo info_;
  bool loopback_ = false;
  protocol::Statistics statistics_{};
  bool streaming_ = false;
  std::string message_;
  nlohmann::json scan_;
  nlohmann::json settings_;
  HostFigures host_;
  std::vector<std::int64_t> receivedNs_;  // the last two seconds of frames
  std::vector<double> captureToHostMs_;   // the last frames
  std::vector<std::uint8_t> confidence_;  // quantised for the page
  double messageBytes_ = 0.0;
  std::uint64_t messages_ = 0;
  std::int64_t cpuNsAtRefresh_ = 0;
  std::int64_t wallNsAtRefresh_ = 0;
  std::int64_t cpuNsAtStart_ = 0;
  std::int64_t wallNsAtStart_ = 0;
  LiveControls controls_;
};

}  // namespace smx::host
