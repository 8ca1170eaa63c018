#include "smx/calib/calibrate.hpp"

#include <cstdio>

#include "smx/calib/capture_set.hpp"
#include "smx/calib/joint_refinement.hpp"

namespace smx::calib {
namespace {

std::string px(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f px", v);
  return buf;
}

std::expected<void, std::string> checkSolved(const ProjectorFit& fit) {
  if (fit.rmsPx <= kFailProjectorRmsPx) {
    return {};
  }
  return std::unexpected(fit.projector.id + ": the solve failed: its stripes fit to " +
                         px(fit.rmsPx) + ", far above the " + px(kGoodProjectorRmsPx) +
                         " of a good set (projector moved between poses, or frames of another "
                         "projector?): capture the set again");
}

}  // namespace

std::expected<Calibration, std::string> calibrate(const algo::Rig& nominal,
                                                  const std::filesystem::path& dir) {
  auto set = openCaptureSet(dir, nominal);
  if (!set) {
    return std::unexpected(set.error());
  }
  if (auto usable = checkCaptureSet(*set, nominal); !usable) {
    return std::unexpected(usable.error());
  }
  auto cameras = calibrateCameras(*set, nominal);
  if (!cameras) {
    return std::unexpected(cameras.error());
  }
  Calibration out;
  out.notes = set->notes;
  out.notes.insert(out.notes.end(), cameras->notes.begin(), cameras->notes.end());
  std::vector<std::vector<StripeSample>> samples;
  for (std::size_t p = 0; p < nominal.projectors.size(); ++p) {
    auto decoded = stripeSamples(*set, *cameras, nominal, p, out.notes);
    if (!decoded) {
      return std::unexpected(decoded.error());
    }
    auto fit = fitProjector(nominal.projectors[p], *decoded, *set);
    if (!fit) {
      return std::unexpected(fit.error());
    }
    if (auto solved = checkSolved(*fit); !solved) {
      return std::unexpected(solved.error());
    }
    samples.push_back(std::move(*decoded));
    out.projectors.push_back(std::move(*fit));
  }
  auto joint = refineJointly(*set, nominal, *cameras, out.projectors, samples);
  if (!joint) {
    return std::unexpected(joint.error());
  }
  out.joint = *joint;
  for (const ProjectorFit& fit : out.projectors) {
    if (auto solved = checkSolved(fit); !solved) {
      return std::unexpected(solved.error());
    }
  }
  for (const CameraFit& fit : cameras->cameras) {
    out.rig.cameras.push_back(fit.camera);
  }
  for (const ProjectorFit& fit : out.projectors) {
    out.rig.projectors.push_back(fit.projector);
  }
  out.cameras = std::move(cameras->cameras);
  out.targets = std::move(cameras->targets);
  std::string check;
  for (const CameraFit& fit : out.cameras) {
    if (fit.rmsPx > kGoodCameraRmsPx) {
      check += (check.empty() ? "" : "; ") + fit.camera.id + " reprojects to " + px(fit.rmsPx) +
               " (target not flat, or blurred frames?)";
    }
  }
  for (const ProjectorFit& fit : out.projectors) {
    if (fit.rmsPx > kGoodProjectorRmsPx) {
      check += (check.empty() ? "" : "; ") + fit.projector.id + " stripes fit to " + px(fit.rmsPx) +
               " (projector moved between poses, or the room light changed?)";
    }
  }
  out.verdict = check.empty() ? "good" : "check: " + check;
  return out;
}

}  // namespace smx::calib
