#pragma once

#include <chrono>
#include <expected>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "device_client.hpp"
#include "smx/algo/rig.hpp"
#include "smx/calib/target.hpp"

// The guided calibration capture (docs/cli.md, "capture --guided"): for each pose it watches
// projector-off frames until the checkerboard is found in the first camera and holds still,
// refuses a pose too like an earlier one, then captures one frame per projector and the off frame
// again (the board must not have moved), writes DIR/poseNN/ in the calibration layout (<cam>.png,
// <proj>.<cam>.png), and prints the corners found and the coverage of the image and tilts so far.
namespace smx::host {

struct CaptureGuideOptions {
  int poses = 12;
  // The target when DIR/target.json does not exist (it is then written); 0 = not given. When the
  // file exists, given values must agree with it.
  int cols = 0;  // inner corners
  int rows = 0;
  double squareM = 0;
  // Still: no corner moves more than this between two consecutive frames.
  double stillPx = 0.5;
  // Too similar: the board's normal within similarDeg and its centre within similarCentre (a
  // fraction of the image diagonal) of an accepted pose's, in the first camera.
  double similarDeg = 5.0;
  double similarCentre = 0.05;
  std::chrono::milliseconds poseTimeout{120'000};    // for each pose, to find a new still board
  std::chrono::milliseconds captureTimeout{10'000};  // for each raw capture
  int gridCols = 8;                                  // the coverage grid over the image
  int gridRows = 6;
};

struct PoseSummary {
  std::string name;                   // "pose00"
  std::vector<int> cornersPerCamera;  // 0 where the board was not found
  double tiltDeg = 0;                 // board normal against the first camera's axis
  double centreX = 0, centreY = 0;    // of the corners in the first camera, px
};

struct CaptureSummary {
  std::vector<PoseSummary> poses;
  int cellsHit = 0;  // coverage grid cells of the first camera holding a corner of some pose
  int cells = 0;
};

// DIR/target.json when it exists (given values must agree with it; 0 = not given), else the
// given target, written there.
[[nodiscard]] std::expected<calib::Target, std::string> resolveCaptureTarget(
    const std::filesystem::path& dir, int cols, int rows, double squareM);

// v with one decimal, as the guided captures print angles and sizes.
[[nodiscard]] std::string oneDecimal(double v);

// "9x6" → {9, 6}: the --target option's inner corners COLSxROWS, or why not.
[[nodiscard]] std::expected<std::pair<int, int>, std::string> parseInnerCorners(
    const std::string& text);

[[nodiscard]] std::expected<CaptureSummary, std::string> captureCalibrationSet(
    DeviceClient& device, const algo::Rig& rig, const CaptureGuideOptions& options,
    const std::filesystem::path& dir, const CliStreams& io);

}  // namespace smx::host
