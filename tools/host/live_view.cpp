#include "live_view.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "config_presets.hpp"
#include "device_option.hpp"
#include "smx/algo/lens.hpp"
#include "smx/view/messages.hpp"

namespace smx::host {

namespace {

constexpr std::int64_t kWindowNs = 2'000'000'000;
constexpr int kRayStep = 2;  // the page's point cloud takes every second pixel
constexpr std::size_t kLatencyWindow = 64;
constexpr std::uint16_t kDefaultPagePort = 8088;

std::int64_t cpuNs() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  const auto ns = [](const timeval& t) {
    return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 +
           static_cast<std::int64_t>(t.tv_usec) * 1000;
  };
  return ns(usage.ru_utime) + ns(usage.ru_stime);
}

// The camera's undistorted rays (x/z, y/z) every kRayStep pixels; NaN where the distortion
// cannot be inverted (the page draws no point there).
std::vector<float> cameraRays(const algo::Camera& camera) {
  std::vector<float> xy;
  for (int y = 0; y < camera.height; y += kRayStep) {
    for (int x = 0; x < camera.width; x += kRayStep) {
      const auto p =
          algo::lens::devicePoint(camera, {static_cast<double>(x), static_cast<double>(y)}, 1.0);
      xy.push_back(p ? static_cast<float>((*p)[0]) : std::nanf(""));
      xy.push_back(p ? static_cast<float>((*p)[1]) : std::nanf(""));
    }
  }
  return xy;
}

nlohmann::json statisticsJson(const protocol::Statistics& s) {
  return {{"uptime_ms", s.uptimeMs},
          {"frames_captured", s.framesCaptured},
          {"frames_decoded", s.framesDecoded},
          {"frames_sent", s.framesSent},
          {"frames_dropped", s.framesDropped},
          {"capture_errors", s.captureErrors},
          {"protocol_errors", s.protocolErrors},
          {"decode_time_us_mean", s.decodeTimeUsMean}};
}

}  // namespace

void addPageOptions(CLI::App& cmd, view::ServerOptions& options, const std::string& prefix,
                    CLI::Option* needs) {
  options.port = kDefaultPagePort;
  auto* bind = cmd.add_option(prefix + "bind", options.bind,
                              "Address the page is served on (default 127.0.0.1: this machine "
                              "only; 0.0.0.0: every network)");
  auto* port = cmd.add_option(prefix + "port", options.port,
                              "Port of the page (default 8088; 0: any free port)");
  if (needs != nullptr) {
    bind->needs(needs);
    port->needs(needs);
  }
}

std::expected<std::unique_ptr<LiveView>, std::string> LiveView::start(
    const view::ServerOptions& options) {
  std::unique_ptr<LiveView> live(new LiveView());
  auto server = view::ViewServer::start(live->feed_, options);
  if (!server) {
    return std::unexpected(server.error());
  }
  live->server_ = std::move(*server);
  live->cpuNsAtStart_ = live->cpuNsAtRefresh_ = cpuNs();
  live->wallNsAtStart_ = live->wallNsAtRefresh_ = view::monotonicNs();
  return live;
}

void LiveView::setDevice(const DeviceInfo& info, const LiveControls& controls) {
  info_ = info;
  controls_ = controls;
  loopback_ = isLoopback(info.address);
  nlohmann::json cameras = nlohmann::json::array();
  std::vector<std::vector<std::byte>> rays;
  for (std::size_t c = 0; c < info.rig.cameras.size(); ++c) {
    const algo::Camera& camera = info.rig.cameras[c];
    cameras.push_back({{"id", camera.id},
                       {"width", camera.width},
                       {"height", camera.height},
                       {"r", camera.R},
                       {"t", camera.t}});
    rays.push_back(view::raysMessage(static_cast<std::uint8_t>(c), camera.width, camera.height,
                                     kRayStep, cameraRays(camera)));
  }
  nlohmann::json presets = nlohmann::json::array();
  for (const auto& p : configPresets()) {
    presets.push_back(p.name);
  }
  feed_.setStaticMessages(std::move(rays));
  feed_.setSession({{"type", "session"},
                    {"device",
                     {{"address", info.address},
                      {"board", info.board},
                      {"firmware", info.firmwareVersion},
                      {"cameras", info.cameras},
                      {"projectors", info.projectors},
                      {"width", info.width},
                      {"height", info.height},
                      {"fps", info.fps},
                      {"depth_unit_m", info.depthUnitM}}},
                    {"cameras", cameras},
                    {"presets", presets}});
}

void LiveView::setSettings(const std::string& document) {
  auto settings = nlohmann::json::parse(document, nullptr, false);
  if (settings.is_discarded() || !settings.is_object()) {
    settings_ = nullptr;
    return;
  }
  settings.erase("format");
  if (settings.contains("rig")) {
    settings["rig"] = "installed";  // the whole rig.json is no use in a table
  }
  settings_ = std::move(settings);
}

void LiveView::frame(const ReceivedFrame& frame) {
  const auto& h = frame.header;
  auto depth = algo::ConstDepthPlane::packed(std::span(frame.depth), h.width, h.height);
  if (!depth) {
    return;  // receiveRangeFrame checked the size; nothing to show otherwise
  }
  auto message = view::depthMessage(h.camera, 0, h.frame, *depth, pageConfidence(frame));
  if (loopback_) {
    captureToHostMs_.push_back(static_cast<double>(frame.receivedNs - h.captureTimestampNs) / 1e6);
  }
  received(frame.receivedNs, message.size());
  feed_.publishFrame(h.camera, std::move(message), frame.receivedNs);
}

algo::ImageView<const std::uint8_t> LiveView::pageConfidence(const ReceivedFrame& frame) {
  const int width = frame.header.width / kConfidenceStep;
  const int height = frame.header.height / kConfidenceStep;
  if (frame.confidence.empty() || width == 0 || height == 0) {
    return {};
  }
  // The page shows confidence at half size in 16 grey levels; so reduced, the plane codes in a
  // quarter of the pixels and about half the bytes each.
  confidence_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::uint8_t v =
          frame.confidence[static_cast<std::size_t>(y * kConfidenceStep) * frame.header.width +
                           static_cast<std::size_t>(x * kConfidenceStep)];
      confidence_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                  static_cast<std::size_t>(x)] = v == 0 ? 0 : static_cast<std::uint8_t>(v | 0x0FU);
    }
  }
  auto plane = algo::ImageView<const std::uint8_t>::packed(std::span(std::as_const(confidence_)),
                                                           width, height);
  return plane ? *plane : algo::ImageView<const std::uint8_t>{};
}

void LiveView::depth(std::size_t camera, int width, int height,
                     const std::vector<std::uint16_t>& depth, std::uint64_t deviceFrame) {
  auto plane = algo::ConstDepthPlane::packed(std::span(depth), width, height);
  if (!plane) {
    return;
  }
  auto message = view::depthMessage(static_cast<std::uint8_t>(camera), 0, deviceFrame, *plane, {});
  const std::int64_t now = view::monotonicNs();
  received(now, message.size());
  feed_.publishFrame(camera, std::move(message), now);
}

void LiveView::view(const scan::RangeView& view) {
  for (std::size_t c = 0; c < view.cameras.size(); ++c) {
    const auto& range = view.cameras[c];
    depth(c, range.width, range.height, range.depth, 0);
  }
}

void LiveView::received(std::int64_t receivedNs, std::size_t messageBytes) {
  receivedNs_.push_back(receivedNs);
  std::erase_if(receivedNs_, [&](std::int64_t t) { return receivedNs - t > kWindowNs; });
  if (captureToHostMs_.size() > kLatencyWindow) {
    captureToHostMs_.erase(captureToHostMs_.begin());
  }
  messageBytes_ += static_cast<double>(messageBytes);
  ++messages_;
}

void LiveView::model(const scan::Cloud& cloud) {
  const std::size_t stride = cloud.size() / kModelPoints + 1;
  std::vector<float> xyz;
  std::vector<std::uint8_t> rgb;
  const bool coloured = cloud.colours.size() == cloud.size();
  for (std::size_t i = 0; i < cloud.size(); i += stride) {
    for (int k = 0; k < 3; ++k) {
      xyz.push_back(static_cast<float>(cloud.points[i][k]));
      const double c = coloured ? cloud.colours[i][k] : 0.8;
      rgb.push_back(static_cast<std::uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255.0)));
    }
  }
  feed_.publishModel(view::modelMessage(0, xyz, rgb));
}

void LiveView::refresh() {
  const std::int64_t now = view::monotonicNs();
  const std::int64_t cpu = cpuNs();
  if (now - wallNsAtRefresh_ >= 500'000'000) {
    host_.cpuPercent = 100.0 * static_cast<double>(cpu - cpuNsAtRefresh_) /
                       static_cast<double>(now - wallNsAtRefresh_);
    cpuNsAtRefresh_ = cpu;
    wallNsAtRefresh_ = now;
  }
  host_.cpuPercentRun = now > wallNsAtStart_ ? 100.0 * static_cast<double>(cpu - cpuNsAtStart_) /
                                                   static_cast<double>(now - wallNsAtStart_)
                                             : 0.0;
  const auto recent =
      std::ranges::count_if(receivedNs_, [&](std::int64_t t) { return now - t <= kWindowNs; });
  host_.receivedPerSecond = static_cast<double>(recent) * 1e9 / static_cast<double>(kWindowNs);
  double sum = 0.0;
  for (const double ms : captureToHostMs_) {
    sum += ms;
  }
  host_.captureToHostMs =
      captureToHostMs_.empty() ? 0.0 : sum / static_cast<double>(captureToHostMs_.size());
  host_.pageKibPerFrame =
      messages_ == 0 ? 0.0 : messageBytes_ / static_cast<double>(messages_) / 1024.0;
  const nlohmann::json status{
      {"streaming", streaming_},
      {"device", statisticsJson(statistics_)},
      {"host",
       {{"received_per_s", host_.receivedPerSecond},
        {"capture_to_host_ms",
         loopback_ ? nlohmann::json(host_.captureToHostMs) : nlohmann::json(nullptr)},
        {"page_kib_per_frame", host_.pageKibPerFrame},
        {"cpu_percent", host_.cpuPercent}}},
      {"scan", scan_},
      {"settings", settings_},
      {"message", message_},
      {"controls",
       {{"start", controls_.stream && !streaming_},
        {"stop", controls_.stream && streaming_},
        {"preset", controls_.presets},
        {"apply-preset", controls_.presets},
        {"config", controls_.presets},
        {"set-config", controls_.presets},
        {"scan-turntable", controls_.startScans},
        {"scan-handheld", controls_.startScans},
        {"stop-scan", controls_.stopScan}}}};
  feed_.setStatus(status);
}

}  // namespace smx::host
