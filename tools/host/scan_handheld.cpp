#include "scan_handheld.hpp"

#include <map>
#include <vector>

#include "smx/text/printf_text.hpp"

namespace smx::host {

namespace {

using Clock = std::chrono::steady_clock;

scan::RangeView viewOf(std::vector<ReceivedFrame>& frames, const DeviceInfo& info) {
  scan::RangeView view;
  view.id =
      text::printfText("%05llu", static_cast<unsigned long long>(frames.front().header.frame));
  view.depthUnitM = info.depthUnitM;
  view.captureNs = frames.front().header.captureTimestampNs;
  view.cameras.resize(static_cast<std::size_t>(info.cameras));
  for (auto& frame : frames) {
    auto& range = view.cameras.at(frame.header.camera);
    range.width = frame.header.width;
    range.height = frame.header.height;
    range.depth = std::move(frame.depth);
  }
  return view;
}

}  // namespace

std::expected<HandheldTally, std::string> trackHandheld(
    DeviceClient& client, scan::Tracker& tracker, const HandheldCaptureOptions& options,
    const std::atomic<bool>& stop,
    const std::function<std::expected<void, std::string>(const scan::RangeView&,
                                                         const scan::TrackResult&)>& tracked) {
  const DeviceInfo& info = client.info();
  if (auto started = client.startStream(protocol::Compression::kRvl); !started) {
    return std::unexpected(started.error());
  }
  HandheldTally tally;
  // Captures still missing a camera's frame; a frame number only grows, so older ones are gone.
  std::map<std::uint64_t, std::vector<ReceivedFrame>> pending;
  auto lastFrame = Clock::now();
  bool stopping = false;
  while (true) {
    auto event = client.next(std::chrono::milliseconds(100));
    if (!event) {
      return std::unexpected(event.error());
    }
    if (event->kind == DeviceEvent::Kind::kStatistics && stopping) {
      tally.device = event->statistics;
      return tally;
    }
    if (event->kind == DeviceEvent::Kind::kFrame && !stopping) {
      lastFrame = Clock::now();
      const std::uint64_t number = event->frame.header.frame;
      auto& frames = pending[number];
      frames.push_back(std::move(event->frame));
      if (std::ssize(frames) == info.cameras) {
        const scan::RangeView view = viewOf(frames, info);
        pending.erase(pending.begin(), pending.upper_bound(number));
        const auto start = Clock::now();
        const scan::TrackResult result = tracker.track(view);
        tally.trackMsTotal +=
            std::chrono::duration<double, std::milli>(Clock::now() - start).count();
        ++tally.captures;
        tally.fused += result.fused ? 1 : 0;
        tally.lost += result.state == scan::TrackingState::kLost ? 1 : 0;
        tally.relocalised += result.state == scan::TrackingState::kRelocalised ? 1 : 0;
        if (auto ok = tracked(view, result); !ok) {
          return std::unexpected(ok.error());
        }
      }
    }
    if (!stopping && (stop.load() || (options.frames > 0 && tally.captures >= options.frames))) {
      if (auto stopped = client.stopStream(); !stopped) {
        return std::unexpected(stopped.error());
      }
      stopping = true;
      lastFrame = Clock::now();
    }
    if (Clock::now() - lastFrame > options.frameTimeout) {
      return std::unexpected(stopping
                                 ? std::string("no statistics after stop-stream")
                                 : "no range frame for " +
                                       std::to_string(options.frameTimeout.count() / 1000) + " s");
    }
  }
}

}  // namespace smx::host
