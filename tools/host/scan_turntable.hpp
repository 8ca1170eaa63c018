#pragma once

#include <expected>
#include <functional>
#include <string>
#include <vector>

#include "device_client.hpp"
#include "smx/scan/range_view.hpp"

// A turntable scan's captures (`stripemux scan --turntable`, docs/scanning.md): the device turns
// the table to each angle and settles; the host takes one frame of every camera with the
// projectors off (the colour) and the first range frames captured after the settle.
namespace smx::host {

struct TurntableCaptureOptions {
  int views = 24;
  bool colour = true;
  std::chrono::milliseconds moveTimeout{60000};
  std::chrono::milliseconds frameTimeout{10000};
};

struct TurntableStep {
  int view = 0;  // 0-based
  int views = 0;
  double angleDeg = 0.0;
  std::size_t points = 0;  // depth pixels over the view's cameras
};

// Each view as it is taken goes to `taken` (which may write it and print progress; an error it
// returns ends the scan). Ends with the table back where it started.
[[nodiscard]] std::expected<std::vector<scan::RangeView>, std::string> captureTurntableViews(
    DeviceClient& client, const TurntableCaptureOptions& options,
    const std::function<std::expected<void, std::string>(const scan::RangeView&,
                                                         const TurntableStep&)>& taken);

}  // namespace smx::host
