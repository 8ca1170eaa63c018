#include "scan_turntable.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace smx::host {

namespace {

using Clock = std::chrono::steady_clock;

std::string viewId(int index) {
  const std::string n = std::to_string(index);
  return std::string(n.size() < 3 ? 3 - n.size() : 0, '0') + n;
}

std::string failure(const TurntableFailure& f) {
  return f.absent
             ? "the device has no turntable" + (f.message.empty() ? "" : " (" + f.message + ")")
             : f.message;
}

// The first capture after `settledNs` with a range frame of every camera; the stream is stopped
// and drained (up to the statistics that answer stop-stream) before it returns.
std::expected<std::vector<ReceivedFrame>, std::string> settledFrames(
    DeviceClient& client, std::int64_t settledNs, std::chrono::milliseconds timeout) {
  const int cameras = client.info().cameras;
  if (auto started = client.startStream(protocol::Compression::kRvl); !started) {
    return std::unexpected(started.error());
  }
  std::map<std::uint64_t, std::vector<ReceivedFrame>> byCapture;
  std::vector<ReceivedFrame> done;
  const auto deadline = Clock::now() + timeout;
  while (done.empty()) {
    if (Clock::now() > deadline) {
      return std::unexpected("no range frame of every camera within " +
                             std::to_string(timeout.count() / 1000) + " s after the table settled");
    }
    auto event = client.next(std::chrono::milliseconds(250));
    if (!event) {
      return std::unexpected(event.error());
    }
    if (event->kind != DeviceEvent::Kind::kFrame ||
        event->frame.header.captureTimestampNs < settledNs) {
      continue;
    }
    auto& frames = byCapture[event->frame.header.frame];
    frames.push_back(std::move(event->frame));
    if (std::ssize(frames) == cameras) {
      done = std::move(frames);
    }
  }
  if (auto stopped = client.stopStream(); !stopped) {
    return std::unexpected(stopped.error());
  }
  // Frames still on the way come before the statistics that end them.
  while (true) {
    if (Clock::now() > deadline) {
      return std::unexpected("no statistics after stop-stream");
    }
    auto event = client.next(std::chrono::milliseconds(250));
    if (!event) {
      return std::unexpected(event.error());
    }
    if (event->kind == DeviceEvent::Kind::kStatistics) {
      break;
    }
  }
  std::ranges::sort(done, {}, [](const ReceivedFrame& f) { return f.header.camera; });
  return done;
}

}  // namespace

std::expected<std::vector<scan::RangeView>, std::string> captureTurntableViews(
    DeviceClient& client, const TurntableCaptureOptions& options,
    const std::function<std::expected<void, std::string>(const scan::RangeView&,
                                                         const TurntableStep&)>& taken) {
  const DeviceInfo& info = client.info();
  auto start = client.turntableStatus(options.frameTimeout);
  if (!start) {
    return std::unexpected(failure(start.error()));
  }
  if (!start->present) {
    return std::unexpected(std::string("the device has no turntable"));
  }
  std::vector<scan::RangeView> views;
  for (int k = 0; k < options.views; ++k) {
    const auto turn = static_cast<std::int64_t>(
        std::llround(360e6 * static_cast<double>(k) / static_cast<double>(options.views)));
    auto state = client.turnTurntable(protocol::TurnMode::kAbsolute, start->angleUdeg + turn,
                                      options.moveTimeout);
    if (!state) {
      return std::unexpected("view " + std::to_string(k) + ": " + failure(state.error()));
    }
    scan::RangeView view;
    view.id = viewId(k);
    view.depthUnitM = info.depthUnitM;
    view.turntableDeg = static_cast<double>(state->angleUdeg - start->angleUdeg) / 1e6;
    view.cameras.resize(static_cast<std::size_t>(info.cameras));
    if (options.colour) {
      auto raw = client.captureRaw(0, options.frameTimeout);
      if (!raw) {
        return std::unexpected("view " + view.id + ": colour frame: " + raw.error());
      }
      for (std::size_t c = 0; c < raw->images.size() && c < view.cameras.size(); ++c) {
        auto& colour = view.cameras[c].colour;
        colour.reserve(raw->images[c].size());
        for (const algo::Rgb8& p : raw->images[c]) {
          colour.push_back({p.r, p.g, p.b});
        }
      }
    }
    auto frames = settledFrames(client, state->settledNs, options.frameTimeout);
    if (!frames) {
      return std::unexpected("view " + view.id + ": " + frames.error());
    }
    std::size_t points = 0;
    for (auto& frame : *frames) {
      auto& range = view.cameras.at(frame.header.camera);
      range.width = frame.header.width;
      range.height = frame.header.height;
      range.depth = std::move(frame.depth);
      points += static_cast<std::size_t>(
          std::ranges::count_if(range.depth, [](std::uint16_t z) { return z != 0; }));
      view.captureNs = frame.header.captureTimestampNs;
    }
    const TurntableStep step{
        .view = k, .views = options.views, .angleDeg = *view.turntableDeg, .points = points};
    if (auto ok = taken(view, step); !ok) {
      return std::unexpected(ok.error());
    }
    views.push_back(std::move(view));
  }
  if (auto back = client.turnTurntable(protocol::TurnMode::kAbsolute, start->angleUdeg,
                                       options.moveTimeout);
      !back) {
    return std::unexpected("turning the table back: " + failure(back.error()));
  }
  return views;
}

}  // namespace smx::host
