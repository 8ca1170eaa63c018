#include "sim_table_calibration.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <nlohmann/json.hpp>
#include <numbers>

#include "smx/algo/lens.hpp"

namespace smx::host {

namespace {

namespace lens = algo::lens;
constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr double kLeanBackDeg = 50.0;
constexpr double kSpanDeg = 40.0;
constexpr double kTableBelowAxisM = 0.10;

nlohmann::ordered_json vecJson(const sim::Vec3& v) {
  return nlohmann::ordered_json::array({v.x(), v.y(), v.z()});
}

}  // namespace

TableLine defaultTableLine(const algo::Rig& rig) {
  const auto& camera = rig.cameras.front();
  const auto onAxis = lens::toWorld(camera, {0.0, 0.0, workingDistanceM(rig)});
  TableLine line;
  // World up is −y only for a level rig; take the first camera's up instead.
  const Eigen::Matrix3d r =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(camera.R.data());
  line.direction = -(r.transpose() * sim::Vec3::UnitY());
  line.point = sim::Vec3(onAxis[0], onAxis[1], onAxis[2]) - kTableBelowAxisM * line.direction;
  return line;
}

std::vector<double> tableAngles(int count) {
  std::vector<double> angles;
  angles.reserve(static_cast<std::size_t>(std::max(count, 0)));
  for (int i = 0; i < count; ++i) {
    angles.push_back(count == 1 ? 0.0 : -kSpanDeg + 2.0 * kSpanDeg * i / (count - 1));
  }
  return angles;
}

std::vector<TargetPose> tableTargetPoses(const calib::Target& target, const TableLine& line,
                                         std::span<const double> anglesDeg) {
  // Leaning back about the world x axis: the sheet's top moves away from the cameras.
  const sim::Mat3 lean(Eigen::AngleAxisd(-kLeanBackDeg * kRadPerDeg, sim::Vec3::UnitX()));
  const sim::Vec3 centre(0.5 * (target.cols - 1) * target.squareM,
                         0.5 * (target.rows - 1) * target.squareM, 0.0);
  // The sheet's centre sits on the axis, half its height above the table top.
  const sim::Vec3 sheetCentre = line.point + 0.5 * (target.rows + 3) * target.squareM *
                                                 std::sin(kLeanBackDeg * kRadPerDeg) *
                                                 line.direction;
  std::vector<TargetPose> poses;
  for (const double angle : anglesDeg) {
    const sim::Mat3 turn(Eigen::AngleAxisd(angle * kRadPerDeg, line.direction));
    TargetPose pose;
    pose.R = turn * lean;
    pose.t = turn * (sheetCentre - lean * centre - line.point) + line.point;
    poses.push_back(pose);
  }
  return poses;
}

std::string tableViewName(int index) {
  const std::string n = std::to_string(index);
  return "view" + std::string(n.size() < 2 ? 2 - n.size() : 0, '0') + n;
}

std::string tableCapturesJson(std::span<const double> anglesDeg) {
  nlohmann::ordered_json views = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < anglesDeg.size(); ++i) {
    views.push_back({{"id", tableViewName(static_cast<int>(i))}, {"angle_deg", anglesDeg[i]}});
  }
  const nlohmann::ordered_json doc = {{"format", kTableCapturesFormat}, {"views", views}};
  return doc.dump(2) + "\n";
}

std::string tableLineJson(const TableLine& line) {
  const nlohmann::ordered_json doc = {{"direction", vecJson(line.direction)},
                                      {"point", vecJson(line.point)}};
  return doc.dump(2) + "\n";
}

}  // namespace smx::host
