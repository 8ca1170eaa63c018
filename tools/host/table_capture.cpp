#include "table_capture.hpp"

#include <cmath>
#include <cstdint>
#include <ostream>
#include <vector>

#include "calib_capture.hpp"
#include "output_files.hpp"
#include "sim_table_calibration.hpp"
#include "smx/calib/camera_calibration.hpp"
#include "smx/calib/target.hpp"

namespace smx::host {

namespace {

namespace fs = std::filesystem;
using Fail = std::unexpected<std::string>;

// Fewer views or a smaller span than these cannot give the axis (calib::calibrateTable).
constexpr int kMinViews = 4;
constexpr double kMinSpanDeg = 30.0;

std::string degrees(double deg) {
  return oneDecimal(deg) + " deg";
}

std::string failure(const TurntableFailure& f) {
  return f.absent ? "the device has no turntable" : f.message;
}

// Turns the table to `angleUdeg` and takes the frame of every camera there; writes the view.
std::expected<double, std::string> captureView(DeviceClient& device, const algo::Rig& rig,
                                               const calib::Target& target,
                                               const TableCaptureOptions& options,
                                               std::int64_t angleUdeg, const fs::path& viewDir) {
  auto state = device.turnTurntable(protocol::TurnMode::kAbsolute, angleUdeg, options.moveTimeout);
  if (!state) {
    return Fail(failure(state.error()));
  }
  auto frame = device.captureRaw(0, options.captureTimeout);
  if (!frame) {
    return Fail(frame.error());
  }
  if (frame->images.size() != rig.cameras.size()) {
    return Fail("the device sent " + std::to_string(frame->images.size()) +
                " camera images for a rig of " + std::to_string(rig.cameras.size()) + " cameras");
  }
  bool found = false;
  for (const auto& image : frame->images) {
    const auto view = algo::ConstRgbView::packed(image, frame->width, frame->height);
    found = found || (view && !calib::findTargetCorners(target, *view).empty());
  }
  const double angleDeg = static_cast<double>(state->angleUdeg) / 1e6;
  if (!found) {
    return Fail("the target is not found whole in any camera at " + degrees(angleDeg) +
                ": lean it on the table so that every camera sees it at every angle, or give a "
                "smaller --span");
  }
  auto out = OutputFolder::create(viewDir);
  if (!out) {
    return Fail(out.error());
  }
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    const auto image = *algo::ConstRgbView::packed(frame->images[c], frame->width, frame->height);
    if (auto ok = writePngRgb8(*out, rig.cameras[c].id + ".png", image); !ok) {
      return Fail(ok.error());
    }
  }
  if (auto ok = out->commit(); !ok) {
    return Fail(ok.error());
  }
  return angleDeg;
}

}  // namespace

std::expected<int, std::string> captureTableSet(DeviceClient& device, const algo::Rig& rig,
                                                const TableCaptureOptions& options,
                                                const fs::path& dir, const CliStreams& io) {
  if (rig.cameras.empty()) {
    return Fail("the rig has no camera");
  }
  if (options.views < kMinViews || !(options.spanDeg >= kMinSpanDeg) || options.spanDeg > 360.0) {
    return Fail("the axis needs at least " + std::to_string(kMinViews) + " views over " +
                degrees(kMinSpanDeg) + " to 360 deg");
  }
  auto start = device.turntableStatus(options.moveTimeout);
  if (start && !start->present) {
    start = std::unexpected(TurntableFailure{true, ""});
  }
  if (!start) {
    return Fail(failure(start.error()));
  }
  const auto target = resolveCaptureTarget(dir, options.cols, options.rows, options.squareM);
  if (!target) {
    return Fail(target.error());
  }
  io.out << "target: checkerboard of " << target->cols << "x" << target->rows << " inner corners, "
         << target->squareM * 1000 << " mm squares, leaning on the table; " << options.views
         << " views over " << degrees(options.spanDeg) << "\n"
         << std::flush;
  std::vector<double> angles;
  std::string stopped;
  for (int k = 0; k < options.views && stopped.empty(); ++k) {
    const double offsetDeg = options.spanDeg * (static_cast<double>(k) / (options.views - 1) - 0.5);
    const std::string name = tableViewName(k);
    const auto angle = captureView(device, rig, *target, options,
                                   start->angleUdeg + std::llround(offsetDeg * 1e6), dir / name);
    if (!angle) {
      stopped = name + ": " + angle.error();
      continue;
    }
    angles.push_back(*angle);
    io.out << name << ": captured at " << degrees(*angle) << "\n" << std::flush;
  }
  const auto back =
      device.turnTurntable(protocol::TurnMode::kAbsolute, start->angleUdeg, options.moveTimeout);
  if (!stopped.empty()) {
    return Fail(stopped);
  }
  if (!back) {
    return Fail("turning the table back: " + failure(back.error()));
  }
  auto out = OutputFolder::create(dir);
  if (!out) {
    return Fail(out.error());
  }
  if (auto ok = out->writeText("turntable.json", tableCapturesJson(angles)); !ok) {
    return Fail(ok.error());
  }
  if (auto ok = out->commit(); !ok) {
    return Fail(ok.error());
  }
  io.out << "wrote " << angles.size() << " views to " << dir.string() << "\n";
  return static_cast<int>(angles.size());
}

}  // namespace smx::host
