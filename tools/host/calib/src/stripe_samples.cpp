#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/lens.hpp"
#include "smx/calib/projector_calibration.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::calib {
namespace {

// Samples per pose and camera: enough to fit a dozen parameters many times over, few enough
// that the solve stays a few seconds.
constexpr int kSamplesPerView = 4000;

// The projector's light alone, with the target's print divided out: (lit − off) / off scaled by
// the white paper's level. Dark squares then carry the stripes as the light ones do, and the
// squares' edges are no colour edges for the decoder.
sim::RgbImage projectorLight(const sim::RgbImage& lit, const sim::RgbImage& off) {
  std::vector<int> levels;
  levels.reserve(off.pixels.size());
  for (const algo::Rgb8& p : off.pixels) {
    levels.push_back(p.r + p.g + p.b);
  }
  std::vector<int> sorted = levels;
  const auto high = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() * 95 / 100);
  std::nth_element(sorted.begin(), high, sorted.end());
  const double white = std::max(*high, 3);
  const double floor = white / 20.0;  // below: the room light tells nothing of the print
  sim::RgbImage out{.width = lit.width, .height = lit.height, .pixels = lit.pixels};
  for (std::size_t i = 0; i < out.pixels.size(); ++i) {
    const double gain = white / std::max<double>(levels[i], floor);
    const auto channel = [&](std::uint8_t on, std::uint8_t dark) {
      const double v = (static_cast<double>(on) - dark) * gain;
      return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
    };
    out.pixels[i] = {channel(lit.pixels[i].r, off.pixels[i].r),
                     channel(lit.pixels[i].g, off.pixels[i].g),
                     channel(lit.pixels[i].b, off.pixels[i].b)};
  }
  return out;
}

Eigen::Vector3d toEigen(const algo::lens::Point3& p) {
  return {p[0], p[1], p[2]};
}

// The camera's decoded stripe coordinates of the projector, or why none.
std::expected<void, std::string> decodeView(const algo::Camera& camera,
                                            const algo::Projector& projector,
                                            const sim::RgbImage& light, double depthM,
                                            std::vector<std::int32_t>& stripe) {
  algo::Rig rig;
  rig.cameras = {camera};
  rig.projectors = {projector};
  algo::PipelineOptions options;
  options.nominalDepthM = depthM;
  const auto setup = algo::prepareCameraPipeline(rig, 0, options);
  if (!setup) {
    return std::unexpected(setup.error());
  }
  const auto bytes = algo::CameraPipeline::workspaceBytes(*setup);
  if (!bytes) {
    return std::unexpected(bytes.error().message);
  }
  std::vector<std::byte> memory(*bytes);
  algo::Arena arena(memory);
  auto pipeline = algo::CameraPipeline::create(*setup, arena);
  if (!pipeline) {
    return std::unexpected(pipeline.error().message);
  }
  if (auto ok = pipeline->demultiplex(light.view()); !ok) {
    return std::unexpected(ok.error().message);
  }
  if (auto ok = pipeline->decode(); !ok) {
    return std::unexpected(ok.error().message);
  }
  const algo::ConstStripePlane plane = pipeline->stripe(0);
  stripe.assign(static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height),
                algo::kNoStripe);
  for (int y = 0; y < camera.height; ++y) {
    const auto row = plane.row(y);
    std::copy(row.begin(), row.end(),
              stripe.begin() + static_cast<std::ptrdiff_t>(y) * camera.width);
  }
  return {};
}

}  // namespace

std::optional<Eigen::Vector3d> targetPoint(const algo::Camera& camera, const TargetPose& pose,
                                           double x, double y) {
  const auto ray = algo::lens::pixelRay(camera, {x, y});
  if (!ray) {
    return std::nullopt;
  }
  const Eigen::Vector3d o = toEigen(ray->origin);
  const Eigen::Vector3d d = toEigen(ray->direction);
  const Eigen::Vector3d normal = pose.R.col(2);
  const double facing = normal.dot(d);
  if (std::abs(facing) < 1e-6) {
    return std::nullopt;
  }
  return o + d * (normal.dot(pose.t - o) / facing);
}

std::expected<std::vector<StripeSample>, std::string> stripeSamples(
    const CaptureSet& set, const CamerasFit& cameras, const algo::Rig& nominal,
    std::size_t projector, std::vector<std::string>& notes) {
  const algo::Projector& proj = nominal.projectors[projector];
  const Target& target = set.target;
  std::vector<StripeSample> samples;
  std::vector<std::int32_t> stripe;
  for (std::size_t p = 0; p < set.poses.size(); ++p) {
    const PoseFiles& files = set.poses[p];
    const TargetPose& pose = cameras.targets[p];
    if (!pose.known) {
      continue;  // the cameras' notes say why
    }
    for (std::size_t c = 0; c < cameras.cameras.size(); ++c) {
      const algo::Camera& camera = cameras.cameras[c].camera;
      if (files.lit[projector][c].empty() || files.off[c].empty()) {
        continue;  // the capture set's notes name the missing file
      }
      const std::string owner = "camera " + camera.id;  // outlives the limit's view of it
      const auto limit = sim::PngSizeLimit::exactly(camera.width, camera.height, owner);
      const auto unreadable = [&](const std::string& error) {
        return std::unexpected(files.name + ": " + error +
                               ": capture this pose again or remove its folder");
      };
      auto lit = sim::readPngRgb8(files.lit[projector][c], limit);
      if (!lit) {
        return unreadable(lit.error());
      }
      auto off = sim::readPngRgb8(files.off[c], limit);
      if (!off) {
        return unreadable(off.error());
      }
      const Eigen::Vector3d middle =
          pose.R * Eigen::Vector3d((target.cols - 1) * target.squareM / 2,
                                   (target.rows - 1) * target.squareM / 2, 0) +
          pose.t;
      const double depthM =
          toEigen(algo::lens::toDevice(camera, {middle[0], middle[1], middle[2]}))[2];
      if (auto ok = decodeView(camera, proj, projectorLight(*lit, *off), depthM, stripe); !ok) {
        return std::unexpected(files.name + ": " + proj.id + " seen by " + camera.id + ": " +
                               ok.error());
      }
      const auto decoded = static_cast<std::size_t>(
          std::ranges::count_if(stripe, [](std::int32_t s) { return s != algo::kNoStripe; }));
      if (decoded == 0) {
        notes.push_back(files.name + ": no stripe of " + proj.id + " decoded in " + camera.id +
                        " (is the projector on and aimed at the target?)");
        continue;
      }
      const int step =
          std::max(1, static_cast<int>(std::sqrt(static_cast<double>(decoded) / kSamplesPerView)));
      for (int y = 0; y < camera.height; y += step) {
        for (int x = 0; x < camera.width; x += step) {
          const std::int32_t s =
              stripe[(static_cast<std::size_t>(y) * static_cast<std::size_t>(camera.width)) +
                     static_cast<std::size_t>(x)];
          if (s == algo::kNoStripe) {
            continue;
          }
          const auto point =
              targetPoint(camera, pose, static_cast<double>(x), static_cast<double>(y));
          if (!point) {
            continue;
          }
          const Eigen::Vector3d local = pose.R.transpose() * (*point - pose.t);
          // On the printed squares: beyond them the sheet's margin is of unknown size.
          if (local.x() < -target.squareM || local.x() > target.cols * target.squareM ||
              local.y() < -target.squareM || local.y() > target.rows * target.squareM) {
            continue;
          }
          samples.push_back({.x = static_cast<double>(x),
                             .y = static_cast<double>(y),
                             .point = *point,
                             .stripe = static_cast<double>(s) / algo::kStripeOne,
                             .pose = p,
                             .camera = c});
        }
      }
    }
  }
  if (samples.empty()) {
    return std::unexpected(proj.id + ": no stripe decoded on the target in any pose (its frames " +
                           "look unlit): is " + proj.id + " on in its frames and aimed at the " +
                           "target?");
  }
  return samples;
}

}  // namespace smx::calib
