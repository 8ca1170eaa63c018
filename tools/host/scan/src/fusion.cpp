#include "smx/scan/fusion.hpp"

#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>

#include <cmath>
#include <cstring>

#include "open3d_bridge.hpp"
#include "smx/algo/lens.hpp"

namespace smx::scan {
namespace {

using open3d::geometry::Image;
namespace integration = open3d::pipelines::integration;

// Grey for cameras without a colour image.
constexpr std::uint8_t kNoColour = 180;

// A camera as Open3D integrates it: the pinhole camera of the same K (no distortion) and, per
// pixel of that pinhole image, the pixel of the real (distorted) image that sees the same ray
// nearest, or -1 outside it. Nearest neighbour on purpose: interpolating depth would invent
// surfaces between a foreground edge and the background.
struct PinholeCamera {
  open3d::camera::PinholeCameraIntrinsic intrinsic;
  Eigen::Matrix4d fromRig = Eigen::Matrix4d::Identity();  // rig → camera
  std::vector<std::int64_t> source;                       // pinhole pixel → real pixel or -1
};

PinholeCamera pinholeOf(const algo::Camera& camera) {
  PinholeCamera out;
  Eigen::Matrix3d k;
  k << camera.K[0], camera.K[1], camera.K[2], camera.K[3], camera.K[4], camera.K[5], camera.K[6],
      camera.K[7], camera.K[8];
  out.intrinsic = open3d::camera::PinholeCameraIntrinsic(camera.width, camera.height, k);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      out.fromRig(r, c) = camera.R[(3 * static_cast<std::size_t>(r)) + static_cast<std::size_t>(c)];
    }
    out.fromRig(r, 3) = camera.t[static_cast<std::size_t>(r)];
  }
  out.source.assign(
      static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height), -1);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      // Pinhole pixel → normalised undistorted coordinates → distorted → real pixel.
      const double yn = (v - camera.cy()) / camera.fy();
      const double xn = (u - camera.cx() - camera.K[1] * yn) / camera.fx();
      const auto d = algo::lens::distort(camera.dist, {xn, yn});
      const double px = camera.fx() * d.x + camera.K[1] * d.y + camera.cx();
      const double py = camera.fy() * d.y + camera.cy();
      const double x = std::round(px);
      const double y = std::round(py);
      if (x < 0 || y < 0 || x > camera.width - 1 || y > camera.height - 1) {
        continue;
      }
      out.source[static_cast<std::size_t>(v) * static_cast<std::size_t>(camera.width) +
                 static_cast<std::size_t>(u)] =
          static_cast<std::int64_t>(y) * camera.width + static_cast<std::int64_t>(x);
    }
  }
  return out;
}

}  // namespace

struct Tsdf::Impl {
  FusionOptions options;
  std::vector<PinholeCamera> cameras;
  integration::ScalableTSDFVolume volume;

  Impl(const algo::Rig& rig, const FusionOptions& o)
      : options(o), volume(o.voxelM, o.truncationM, integration::TSDFVolumeColorType::RGB8) {
    for (const auto& camera : rig.cameras) {
      cameras.push_back(pinholeOf(camera));
    }
  }
};

Tsdf::Tsdf(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Tsdf::Tsdf(Tsdf&&) noexcept = default;
Tsdf& Tsdf::operator=(Tsdf&&) noexcept = default;
Tsdf::~Tsdf() = default;

std::expected<Tsdf, std::string> Tsdf::create(const algo::Rig& rig, const FusionOptions& options) {
  if (rig.cameras.empty()) {
    return std::unexpected("the rig has no camera");
  }
  if (!std::isfinite(options.voxelM) || options.voxelM < 1e-5 || options.voxelM > 0.1) {
    return std::unexpected("the TSDF voxel must be 0.01 mm to 100 mm");
  }
  if (!std::isfinite(options.truncationM) || options.truncationM < options.voxelM ||
      !std::isfinite(options.maxDepthM) || options.maxDepthM <= 0) {
    return std::unexpected("the TSDF truncation must be at least a voxel, the depth positive");
  }
  for (const auto& camera : rig.cameras) {
    if (camera.width < 1 || camera.height < 1 || camera.fx() <= 0 || camera.fy() <= 0) {
      return std::unexpected("camera " + camera.id + " has no valid size or focal length");
    }
  }
  return Tsdf(std::make_unique<Impl>(rig, options));
}

std::expected<void, std::string> Tsdf::integrate(const RangeView& view, const Pose& pose) {
  auto& impl = *impl_;
  const std::size_t count = std::min(view.cameras.size(), impl.cameras.size());
  for (std::size_t c = 0; c < count; ++c) {
    const CameraRange& range = view.cameras[c];
    const PinholeCamera& camera = impl.cameras[c];
    const int width = camera.intrinsic.width_;
    const int height = camera.intrinsic.height_;
    const auto pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    if (range.width != width || range.height != height || range.depth.size() != pixels) {
      return std::unexpected("view " + view.id + ": camera " + std::to_string(c) + " is " +
                             std::to_string(range.width) + "x" + std::to_string(range.height) +
                             ", the rig's is " + std::to_string(width) + "x" +
                             std::to_string(height));
    }
    const bool coloured = range.colour.size() == pixels;
    Image depth;
    depth.Prepare(width, height, 1, 2);
    Image colour;
    colour.Prepare(width, height, 3, 1);
    auto* depthOut = reinterpret_cast<std::uint16_t*>(depth.data_.data());
    std::memset(colour.data_.data(), kNoColour, colour.data_.size());
    for (std::size_t i = 0; i < pixels; ++i) {
      const std::int64_t from = camera.source[i];
      depthOut[i] = from < 0 ? std::uint16_t{0} : range.depth[static_cast<std::size_t>(from)];
      if (coloured && from >= 0) {
        std::memcpy(&colour.data_[3 * i], range.colour[static_cast<std::size_t>(from)].data(), 3);
      }
    }
    const auto rgbd = open3d::geometry::RGBDImage::CreateFromColorAndDepth(
        colour, depth, 1.0 / view.depthUnitM, impl.options.maxDepthM, false);
    impl.volume.Integrate(*rgbd, camera.intrinsic, camera.fromRig * pose.inverse().matrix());
  }
  return {};
}

Cloud Tsdf::extractCloud() const {
  return detail::fromOpen3d(*impl_->volume.ExtractPointCloud());
}

Mesh Tsdf::extractMesh() const {
  auto mesh = impl_->volume.ExtractTriangleMesh();
  mesh->ComputeVertexNormals();
  return detail::fromOpen3d(*mesh);
}

}  // namespace smx::scan
