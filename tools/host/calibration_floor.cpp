#include "calibration_floor.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "smx/algo/lens.hpp"
#include "smx/calib/camera_calibration.hpp"
#include "smx/calib/capture_set.hpp"
#include "smx/calib/projector_calibration.hpp"
#include "smx/calib/target.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::host {

namespace {

namespace fs = std::filesystem;

// The projector fit drops samples beyond this many robust deviations (docs/calibration.md);
// the floor drops the same, so that both figures describe the same kind of sample.
constexpr double kOutlierDeviations = 5.0;
constexpr double kMadToSigma = 1.4826;

std::vector<calib::TargetPose> readTruePoses(const fs::path& file) {
  std::ifstream in(file);
  const auto doc = nlohmann::json::parse(in, nullptr, false);
  if (doc.is_discarded() || !doc.contains("poses")) {
    throw std::runtime_error(file.string() + ": not a stripemux-calibration-truth file");
  }
  std::vector<calib::TargetPose> poses;
  for (const auto& p : doc["poses"]) {
    calib::TargetPose pose{.known = true};
    for (int i = 0; i < 9; ++i) {
      pose.R(i / 3, i % 3) = p["R"][static_cast<std::size_t>(i)].get<double>();
    }
    for (int i = 0; i < 3; ++i) {
      pose.t[i] = p["t"][static_cast<std::size_t>(i)].get<double>();
    }
    poses.push_back(pose);
  }
  return poses;
}

double rms(const std::vector<double>& residuals) {
  double sum = 0;
  for (const double r : residuals) {
    sum += r * r;
  }
  return residuals.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(residuals.size()));
}

// RMS of the residuals within kOutlierDeviations robust deviations of zero.
double robustRms(std::vector<double> residuals) {
  std::vector<double> magnitudes;
  magnitudes.reserve(residuals.size());
  for (const double r : residuals) {
    magnitudes.push_back(std::abs(r));
  }
  if (magnitudes.empty()) {
    return 0.0;
  }
  const auto mid = magnitudes.begin() + static_cast<std::ptrdiff_t>(magnitudes.size() / 2);
  std::ranges::nth_element(magnitudes, mid);
  const double limit = kOutlierDeviations * kMadToSigma * *mid;
  std::erase_if(residuals, [limit](double r) { return std::abs(r) > limit; });
  return rms(residuals);
}

double cornerFloor(const calib::CaptureSet& set, const std::vector<calib::TargetPose>& poses,
                   const algo::Camera& camera, std::size_t c) {
  const std::vector<calib::TargetPoint> grid = calib::innerCorners(set.target);
  std::vector<double> residuals;
  for (std::size_t p = 0; p < set.poses.size() && p < poses.size(); ++p) {
    const fs::path& file = set.poses[p].off[c];
    if (file.empty()) {
      continue;
    }
    const auto image = sim::readPngRgb8(
        file, sim::PngSizeLimit::exactly(camera.width, camera.height, "camera " + camera.id));
    if (!image) {
      throw std::runtime_error(file.string() + ": " + image.error());
    }
    const auto found = calib::findTargetCorners(set.target, image->view());
    for (std::size_t i = 0; i < found.size(); ++i) {
      const Eigen::Vector3d world =
          poses[p].R * Eigen::Vector3d(grid[i].x, grid[i].y, 0) + poses[p].t;
      const auto truth = algo::lens::project(camera, {world[0], world[1], world[2]});
      if (truth) {
        residuals.push_back(found[i][0] - truth->x);
        residuals.push_back(found[i][1] - truth->y);
      }
    }
  }
  // Per coordinate, as the reprojection RMS of the fit (OpenCV's) is counted.
  return rms(residuals) * std::sqrt(2.0);
}

}  // namespace

ResidualFloor truthResiduals(const fs::path& captures, const algo::Rig& real) {
  auto set = calib::openCaptureSet(captures, real);
  if (!set) {
    throw std::runtime_error(captures.string() + ": " + set.error());
  }
  calib::CamerasFit truth;
  truth.targets = readTruePoses(captures / "truth" / "poses.json");
  ResidualFloor floor;
  for (std::size_t c = 0; c < real.cameras.size(); ++c) {
    calib::CameraFit fit;
    fit.camera = real.cameras[c];
    truth.cameras.push_back(std::move(fit));
    floor.cameraRmsPx =
        std::max(floor.cameraRmsPx, cornerFloor(*set, truth.targets, real.cameras[c], c));
  }
  for (std::size_t p = 0; p < real.projectors.size(); ++p) {
    std::vector<std::string> notes;
    const auto samples = calib::stripeSamples(*set, truth, real, p, notes);
    if (!samples) {
      throw std::runtime_error(captures.string() + ": " + samples.error());
    }
    std::vector<double> residuals;
    residuals.reserve(samples->size());
    for (const calib::StripeSample& s : *samples) {
      residuals.push_back(calib::stripeResidualPx(real.projectors[p], s));
    }
    floor.projectorRmsPx = std::max(floor.projectorRmsPx, robustRms(std::move(residuals)));
  }
  return floor;
}

}  // namespace smx::host
