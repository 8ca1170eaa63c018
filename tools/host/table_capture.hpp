#pragma once

#include <chrono>
#include <expected>
#include <filesystem>
#include <string>

#include "cli.hpp"
#include "device_client.hpp"
#include "smx/algo/rig.hpp"

// The guided turntable capture (`stripemux calibrate --device HOST --turntable`,
// docs/calibration.md "Turntable axis"): with the printed target leaning on the table, the device
// turns the table to `views` angles spread evenly over `spanDeg` around where it stands and, once
// it has settled at each, takes a frame of every camera with every projector off. The frames go to
// DIR in the layout calib::calibrateTable() reads: target.json, turntable.json (each view's angle
// as the table reports it) and viewNN/<camera-id>.png. A view in which no camera finds the whole
// target stops the capture, naming the view and its angle. The table is turned back to where it
// stood, after a failure too.
namespace smx::host {

struct TableCaptureOptions {
  int views = 8;
  double spanDeg = 80.0;
  // The target when DIR/target.json does not exist (it is then written); 0 = not given. When the
  // file exists, given values must agree with it.
  int cols = 0;  // inner corners
  int rows = 0;
  double squareM = 0;
  std::chrono::milliseconds moveTimeout{60'000};     // for each turn, settling included
  std::chrono::milliseconds captureTimeout{10'000};  // for each frame
};

// The views written, or why the capture stopped.
[[nodiscard]] std::expected<int, std::string> captureTableSet(DeviceClient& device,
                                                              const algo::Rig& rig,
                                                              const TableCaptureOptions& options,
                                                              const std::filesystem::path& dir,
                                                              const CliStreams& io);

}  // namespace smx::host
