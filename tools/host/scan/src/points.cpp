#include "smx/scan/points.hpp"

#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>

#include <algorithm>

#include "open3d_bridge.hpp"
#include "smx/algo/lens.hpp"

namespace smx::scan {
namespace {

void normaliseNormals(Cloud& cloud) {
  for (auto& n : cloud.normals) {
    const double length = n.norm();
    n = length > 0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::UnitZ();
  }
}

}  // namespace

Cloud cameraPoints(const algo::Camera& camera, const CameraRange& range, double depthUnitM) {
  Cloud cloud;
  const bool coloured = range.colour.size() == range.depth.size() && !range.colour.empty();
  for (int y = 0; y < range.height; ++y) {
    for (int x = 0; x < range.width; ++x) {
      const auto index = static_cast<std::size_t>(y) * static_cast<std::size_t>(range.width) +
                         static_cast<std::size_t>(x);
      const std::uint16_t units = range.depth[index];
      if (units == 0) {
        continue;
      }
      const auto local = algo::lens::devicePoint(
          camera, {static_cast<double>(x), static_cast<double>(y)}, units * depthUnitM);
      if (!local) {
        continue;
      }
      const auto world = algo::lens::toWorld(camera, *local);
      cloud.points.emplace_back(world[0], world[1], world[2]);
      if (coloured) {
        const auto& rgb = range.colour[index];
        cloud.colours.emplace_back(rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0);
      }
    }
  }
  return cloud;
}

Cloud viewCloud(const algo::Rig& rig, const RangeView& view, const CloudOptions& options) {
  const double voxel = std::max(options.voxelM, 0.0);
  const double radius =
      options.normalRadiusM > 0 ? options.normalRadiusM : std::max(3 * voxel, 0.002);
  Cloud merged;
  bool first = true;
  const std::size_t cameras = std::min(rig.cameras.size(), view.cameras.size());
  for (std::size_t c = 0; c < cameras; ++c) {
    const auto& camera = rig.cameras[c];
    const auto& range = view.cameras[c];
    if (range.width != camera.width || range.height != camera.height ||
        range.depth.size() !=
            static_cast<std::size_t>(range.width) * static_cast<std::size_t>(range.height)) {
      continue;
    }
    auto cloud = detail::toOpen3d(cameraPoints(camera, range, view.depthUnitM));
    if (cloud->points_.empty()) {
      continue;
    }
    if (voxel > 0) {
      cloud = cloud->VoxelDownSample(voxel);
    }
    cloud->EstimateNormals(
        open3d::geometry::KDTreeSearchParamHybrid(radius, options.normalNeighbours));
    const auto centre = algo::lens::centre(camera);
    cloud->OrientNormalsTowardsCameraLocation(Eigen::Vector3d(centre[0], centre[1], centre[2]));
    Cloud part = detail::fromOpen3d(*cloud);
    if (first) {
      merged = std::move(part);
      first = false;
    } else {
      append(merged, part);
    }
  }
  return cameras > 1 && voxel > 0 ? downsampled(merged, voxel) : merged;
}

Cloud transformed(const Cloud& cloud, const Pose& pose) {
  Cloud out = cloud;
  for (auto& p : out.points) {
    p = pose * p;
  }
  for (auto& n : out.normals) {
    n = pose.linear() * n;
  }
  return out;
}

Cloud downsampled(const Cloud& cloud, double voxelM) {
  if (cloud.empty() || voxelM <= 0) {
    return cloud;
  }
  Cloud out = detail::fromOpen3d(*detail::toOpen3d(cloud)->VoxelDownSample(voxelM));
  normaliseNormals(out);
  return out;
}

void append(Cloud& cloud, const Cloud& more) {
  const bool normals =
      cloud.normals.size() == cloud.points.size() && more.normals.size() == more.points.size();
  const bool colours =
      cloud.colours.size() == cloud.points.size() && more.colours.size() == more.points.size();
  cloud.points.insert(cloud.points.end(), more.points.begin(), more.points.end());
  if (normals) {
    cloud.normals.insert(cloud.normals.end(), more.normals.begin(), more.normals.end());
  } else {
    cloud.normals.clear();
  }
  if (colours) {
    cloud.colours.insert(cloud.colours.end(), more.colours.begin(), more.colours.end());
  } else {
    cloud.colours.clear();
  }
}

}  // namespace smx::scan
