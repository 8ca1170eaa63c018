#pragma once

#include <atomic>
#include <chrono>
#include <expected>
#include <functional>
#include <string>

#include "device_client.hpp"
#include "smx/scan/tracker.hpp"

// A hand-held scan's stream (`stripemux scan --handheld`, docs/scanning.md): every capture's
// range frames, as they arrive, tracked against the model built so far.
namespace smx::host {

struct HandheldCaptureOptions {
  int frames = 0;  // captures to take; 0: until `stop`
  std::chrono::milliseconds frameTimeout{10000};
};

struct HandheldTally {
  int captures = 0;
  int fused = 0;
  int lost = 0;
  int relocalised = 0;
  double trackMsTotal = 0.0;
  protocol::Statistics device{};  // the device's counters when the stream stopped
};

// Each capture with its tracking goes to `tracked` (which may write it and print; an error it
// returns ends the scan). Ends after options.frames captures, or soon after `stop` is set.
[[nodiscard]] std::expected<HandheldTally, std::string> trackHandheld(
    DeviceClient& client, scan::Tracker& tracker, const HandheldCaptureOptions& options,
    const std::atomic<bool>& stop,
    const std::function<std::expected<void, std::string>(const scan::RangeView&,
                                                         const scan::TrackResult&)>& tracked);

}  // namespace smx::host
