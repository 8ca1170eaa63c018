#include "calib_capture.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "output_files.hpp"
#include "sim_calibration.hpp"
#include "smx/calib/camera_calibration.hpp"
#include "smx/calib/target.hpp"
#include "terminal_text.hpp"

namespace smx::host {

namespace {

namespace fs = std::filesystem;
using Fail = std::unexpected<std::string>;
using Clock = std::chrono::steady_clock;

constexpr double kFrontalDeg = 15.0;  // a tilt below this counts as facing the camera

using calib::Target;

using Corners = std::vector<cv::Point2f>;

// The board's inner corners (calib::findTargetCorners, the calibration's own detector), or empty.
Corners findCorners(const std::vector<algo::Rgb8>& image, int width, int height,
                    const Target& target) {
  Corners corners;
  const auto view = algo::ConstRgbView::packed(image, width, height);
  if (!view) {
    return corners;
  }
  for (const auto& p : calib::findTargetCorners(target, *view)) {
    corners.emplace_back(static_cast<float>(p[0]), static_cast<float>(p[1]));
  }
  return corners;
}

// The largest corner displacement between two detections, either corner order (a symmetric
// board may be found starting from the opposite corner).
double largestMove(const Corners& a, const Corners& b) {
  if (a.size() != b.size() || a.empty()) {
    return std::numeric_limits<double>::infinity();
  }
  double same = 0;
  double reversed = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    same = std::max(same, static_cast<double>(cv::norm(a[i] - b[i])));
    reversed = std::max(reversed, static_cast<double>(cv::norm(a[i] - b[b.size() - 1 - i])));
  }
  return std::min(same, reversed);
}

struct BoardView {
  cv::Vec3d normal;  // unit, in the camera frame
  cv::Point2d centre;
  double tiltDeg = 0;
};

// The board's pose from its corners with the rig's (nominal) intrinsics of the camera.
BoardView boardView(const Corners& corners, const Target& target, const algo::Camera& camera) {
  std::vector<cv::Point3f> object;
  for (int r = 0; r < target.rows; ++r) {
    for (int c = 0; c < target.cols; ++c) {
      object.emplace_back(static_cast<float>(c * target.squareM),
                          static_cast<float>(r * target.squareM), 0.0F);
    }
  }
  const cv::Matx33d k(camera.K.data());
  const cv::Mat dist(1, 5, CV_64F, const_cast<double*>(camera.dist.data()));  // NOLINT: read only
  cv::Vec3d rvec;
  cv::Vec3d tvec;
  cv::solvePnP(object, corners, k, dist, rvec, tvec);
  cv::Matx33d rotation;
  cv::Rodrigues(rvec, rotation);
  BoardView view;
  view.normal = cv::Vec3d(rotation(0, 2), rotation(1, 2), rotation(2, 2));
  for (const auto& p : corners) {
    view.centre += cv::Point2d(p.x, p.y);
  }
  view.centre *= 1.0 / static_cast<double>(corners.size());
  view.tiltDeg = std::acos(std::min(1.0, std::abs(view.normal[2]))) * 180.0 / std::numbers::pi;
  return view;
}

double angleDeg(const cv::Vec3d& a, const cv::Vec3d& b) {
  return std::acos(std::min(1.0, std::abs(a.dot(b)))) * 180.0 / std::numbers::pi;
}

// Which way a tilted board turns, seen from the camera.
const char* tiltDirection(const BoardView& view) {
  if (view.tiltDeg < kFrontalDeg) {
    return "frontal";
  }
  const double x = view.normal[0] * (view.normal[2] < 0 ? -1 : 1);
  const double y = view.normal[1] * (view.normal[2] < 0 ? -1 : 1);
  if (std::abs(x) >= std::abs(y)) {
    return x > 0 ? "right" : "left";
  }
  return y > 0 ? "down" : "up";
}

class Coverage {
 public:
  Coverage(const CaptureGuideOptions& options, int width, int height)
      : cols_(std::max(1, options.gridCols)),
        rows_(std::max(1, options.gridRows)),
        width_(width),
        height_(height),
        hit_(static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_), false) {}

  void add(const Corners& corners, const BoardView& view) {
    for (const auto& p : corners) {
      const int cx =
          std::clamp(static_cast<int>(p.x * static_cast<float>(cols_) / static_cast<float>(width_)),
                     0, cols_ - 1);
      const int cy = std::clamp(
          static_cast<int>(p.y * static_cast<float>(rows_) / static_cast<float>(height_)), 0,
          rows_ - 1);
      hit_[cell(cx, cy)] = true;
    }
    ++tilts_[tiltDirection(view)];
  }
  [[nodiscard]] int hit() const { return static_cast<int>(std::ranges::count(hit_, true)); }
  [[nodiscard]] int cells() const { return cols_ * rows_; }

  void print(std::ostream& out, const std::string& cameraId) const {
    out << "  image coverage (" << cameraId << "): " << hit() << " of " << cells()
        << " cells hold corners\n";
    for (int y = 0; y < rows_; ++y) {
      out << "    ";
      for (int x = 0; x < cols_; ++x) {
        out << (hit_[cell(x, y)] ? '#' : '.');
      }
      out << "\n";
    }
    out << "  tilts so far:";
    for (const char* direction : {"frontal", "left", "right", "up", "down"}) {
      const auto found = tilts_.find(direction);
      out << " " << direction << " " << (found == tilts_.end() ? 0 : found->second);
    }
    out << " (frontal: under " << kFrontalDeg << " degrees)\n";
  }

 private:
  [[nodiscard]] std::size_t cell(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(cols_) +
           static_cast<std::size_t>(x);
  }

  int cols_;
  int rows_;
  int width_;
  int height_;
  std::vector<bool> hit_;
  std::map<std::string, int> tilts_;
};

std::string poseName(std::size_t index) {
  const std::string number = std::to_string(index);
  return "pose" + std::string(number.size() < 2 ? 2 - number.size() : 0, '0') + number;
}

struct Accepted {
  std::string name;
  BoardView view;
};

// Why the board in `view` is too like an accepted pose, or nothing.
std::optional<std::string> tooSimilar(const BoardView& view, const std::vector<Accepted>& accepted,
                                      const CaptureGuideOptions& options, double diagonalPx) {
  const double centreLimit = options.similarCentre * diagonalPx;
  for (const auto& earlier : accepted) {
    const double angle = angleDeg(view.normal, earlier.view.normal);
    const double shift = cv::norm(view.centre - earlier.view.centre);
    if (angle < options.similarDeg && shift < centreLimit) {
      return "too similar to " + earlier.name + ": board normal within " + oneDecimal(angle) +
             " deg (limit " + oneDecimal(options.similarDeg) + ") and centre within " +
             oneDecimal(shift) + " px (limit " + oneDecimal(centreLimit) +
             "); move or tilt the board";
    }
  }
  return std::nullopt;
}

// Captures the pose's projector frames, then the off frame again: every image of a pose must
// show one board pose, so a board that moved meanwhile makes the pose start over (false).
// Writes the pose's images only when it held still.
std::expected<bool, std::string> capturePose(DeviceClient& device, const algo::Rig& rig,
                                             const RawCapture& off, const Corners& corners,
                                             const Target& target,
                                             const CaptureGuideOptions& options,
                                             const fs::path& poseDir) {
  std::vector<RawCapture> lit;
  for (std::size_t p = 0; p < rig.projectors.size(); ++p) {
    auto capture = device.captureRaw(1U << p, options.captureTimeout);
    if (!capture) {
      return Fail(rig.projectors[p].id + " on: " + capture.error());
    }
    lit.push_back(std::move(*capture));
  }
  const auto after = device.captureRaw(0, options.captureTimeout);
  if (!after) {
    return Fail(after.error());
  }
  const Corners again = findCorners(after->images.front(), after->width, after->height, target);
  if (!(largestMove(corners, again) < options.stillPx)) {
    return false;
  }
  auto out = OutputFolder::create(poseDir);
  if (!out) {
    return Fail(out.error());
  }
  const auto write = [&](const RawCapture& capture,
                         const std::string& prefix) -> std::expected<void, std::string> {
    for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
      const auto image =
          *algo::ConstRgbView::packed(capture.images[c], capture.width, capture.height);
      if (auto ok = writePngRgb8(*out, prefix + rig.cameras[c].id + ".png", image); !ok) {
        return ok;
      }
    }
    return {};
  };
  if (auto ok = write(off, ""); !ok) {
    return Fail(ok.error());
  }
  for (std::size_t p = 0; p < rig.projectors.size(); ++p) {
    if (auto ok = write(lit[p], rig.projectors[p].id + "."); !ok) {
      return Fail(ok.error());
    }
  }
  if (auto ok = out->commit(); !ok) {
    return Fail(ok.error());
  }
  return true;
}

}  // namespace

std::string oneDecimal(double v) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << v;
  return s.str();
}

std::expected<calib::Target, std::string> resolveCaptureTarget(const fs::path& dir, int cols,
                                                               int rows, double squareM) {
  const fs::path file = dir / "target.json";
  if (fs::exists(file)) {
    auto target = calib::loadTarget(file);
    if (!target) {
      return target;
    }
    const bool disagrees = (cols != 0 && cols != target->cols) ||
                           (rows != 0 && rows != target->rows) ||
                           (squareM != 0 && squareM != target->squareM);
    if (disagrees) {
      return Fail(file.string() + " describes another target than the options; remove one");
    }
    return target;
  }
  if (cols == 0 || rows == 0 || !(squareM > 0)) {
    return Fail(
        "no target: give its inner corners and square (--target COLSxROWS --square M) "
        "or write " +
        file.string());
  }
  const Target given{.cols = cols, .rows = rows, .squareM = squareM};
  const std::string text = targetJson(given);
  if (auto valid = calib::parseTarget(text); !valid) {
    return Fail("--target/--square: " + valid.error());
  }
  auto out = OutputFolder::create(dir);
  if (!out) {
    return Fail(out.error());
  }
  if (auto ok = out->writeText("target.json", text); !ok) {
    return Fail(ok.error());
  }
  if (auto ok = out->commit(); !ok) {
    return Fail(ok.error());
  }
  return given;
}

std::expected<std::pair<int, int>, std::string> parseInnerCorners(const std::string& text) {
  const auto fail =
      Fail("--target: expected COLSxROWS inner corners, e.g. 9x6, got \"" + printable(text) + "\"");
  const auto x = text.find('x');
  if (x == std::string::npos) {
    return fail;
  }
  try {
    std::size_t used = 0;
    const int cols = std::stoi(text.substr(0, x), &used);
    if (used != x) {
      return fail;
    }
    const int rows = std::stoi(text.substr(x + 1), &used);
    if (used != text.size() - x - 1) {
      return fail;
    }
    return std::pair{cols, rows};
  } catch (const std::exception&) {
    return fail;
  }
}

std::expected<CaptureSummary, std::string> captureCalibrationSet(DeviceClient& device,
                                                                 const algo::Rig& rig,
                                                                 const CaptureGuideOptions& options,
                                                                 const fs::path& dir,
                                                                 const CliStreams& io) {
  if (rig.cameras.empty()) {
    return Fail("the rig has no camera");
  }
  if (options.poses < 1) {
    return Fail("at least one pose is needed");
  }
  const auto target = resolveCaptureTarget(dir, options.cols, options.rows, options.squareM);
  if (!target) {
    return Fail(target.error());
  }
  const algo::Camera& guide = rig.cameras.front();
  const double diagonal = std::hypot(guide.width, guide.height);
  io.out << "target: checkerboard of " << target->cols << "x" << target->rows << " inner corners, "
         << target->squareM * 1000 << " mm squares; hold it still in view "
         << "of " << guide.id << " for each pose\n";

  CaptureSummary summary;
  Coverage coverage(options, guide.width, guide.height);
  std::vector<Accepted> accepted;
  for (int p = 0; p < options.poses; ++p) {
    const std::string name = poseName(static_cast<std::size_t>(p));
    const auto deadline = Clock::now() + options.poseTimeout;
    Corners previous;
    std::string said;
    const auto say = [&](const std::string& text) {
      if (text != said) {
        io.out << name << ": " << text << "\n" << std::flush;
        said = text;
      }
    };
    while (true) {
      if (Clock::now() > deadline) {
        return Fail(name + ": no pose accepted in " +
                    oneDecimal(static_cast<double>(options.poseTimeout.count()) / 1000) +
                    " s: " + (said.empty() ? "no frame arrived" : said));
      }
      auto off = device.captureRaw(0, options.captureTimeout);
      if (!off) {
        return Fail(name + ": " + off.error());
      }
      const Corners corners = findCorners(off->images.front(), off->width, off->height, *target);
      if (corners.empty()) {
        say("the target is not found in " + guide.id);
        previous.clear();
        continue;
      }
      const double move = largestMove(corners, previous);
      previous = corners;
      if (!(move < options.stillPx)) {
        say("target found in " + guide.id + "; waiting for it to hold still");
        continue;
      }
      const BoardView view = boardView(corners, *target, guide);
      if (auto similar = tooSimilar(view, accepted, options, diagonal)) {
        say(*similar);
        continue;
      }
      PoseSummary pose{.name = name,
                       .cornersPerCamera = {static_cast<int>(corners.size())},
                       .tiltDeg = view.tiltDeg,
                       .centreX = view.centre.x,
                       .centreY = view.centre.y};
      for (std::size_t c = 1; c < rig.cameras.size(); ++c) {
        pose.cornersPerCamera.push_back(
            static_cast<int>(findCorners(off->images[c], off->width, off->height, *target).size()));
      }
      const auto held = capturePose(device, rig, *off, corners, *target, options, dir / name);
      if (!held) {
        return Fail(name + ": " + held.error());
      }
      if (!*held) {
        say("the board moved while the projector frames were taken; hold it still");
        previous.clear();
        continue;
      }
      accepted.push_back({name, view});
      coverage.add(corners, view);
      io.out << name << ": captured;";
      for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
        io.out << " " << pose.cornersPerCamera[c] << " of " << target->cols * target->rows
               << " corners in " << rig.cameras[c].id << (c + 1 < rig.cameras.size() ? "," : "");
      }
      io.out << "; tilt " << oneDecimal(view.tiltDeg) << " deg (" << tiltDirection(view) << ")\n";
      coverage.print(io.out, guide.id);
      io.out << std::flush;
      summary.poses.push_back(std::move(pose));
      break;
    }
  }
  summary.cellsHit = coverage.hit();
  summary.cells = coverage.cells();
  io.out << "wrote " << summary.poses.size() << " poses to " << dir.string() << "\n";
  return summary;
}

}  // namespace smx::host
