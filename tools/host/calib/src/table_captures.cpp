#include "smx/calib/table_captures.hpp"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <exception>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "smx/calib/camera_calibration.hpp"
#include "smx/config/field_reader.hpp"
#include "smx/config/identifier.hpp"
#include "smx/config/json_reader.hpp"
#include "smx/sim/png_io.hpp"
#include "smx/text/printf_text.hpp"

namespace smx::calib {
namespace {

namespace fs = std::filesystem;

constexpr std::array<std::string_view, 2> kTopKeys = {"format", "views"};
constexpr std::array<std::string_view, 2> kViewKeys = {"id", "angle_deg"};
constexpr config::DocumentSpec kTableDocument = {.name = "turntable.json",
                                                 .format = kTableCapturesFormat,
                                                 .topKeys = kTopKeys,
                                                 .maxBytes = std::size_t{1} << 16U,
                                                 .sizeNote = "",
                                                 .nestingNeeded = 3,
                                                 .maxNesting = 8,
                                                 .otherFormats = {}};
constexpr double kMaxAngleDeg = 3600.0;

std::string message(const config::FieldError& e) {
  return e.field.empty() ? e.problem : e.field + ": " + e.problem;
}

std::expected<std::vector<TableViewUse>, std::string> parseViews(std::string_view json) {
  auto doc = config::parseDocument(json, kTableDocument);
  if (!doc) {
    return std::unexpected(message(doc.error()));
  }
  config::FieldReader r;
  const nlohmann::json* views = r.find(*doc, "views");
  if (views == nullptr || !views->is_array() || views->empty() ||
      views->size() > static_cast<std::size_t>(kMaxTableViews)) {
    return std::unexpected(
        text::printfText(R"(views: must be an array of 1 to %d views {"id": NAME, "angle_deg": A})",
                         kMaxTableViews));
  }
  std::vector<TableViewUse> out;
  for (std::size_t i = 0; i < views->size(); ++i) {
    const std::string at = "views[" + std::to_string(i) + "]";
    const nlohmann::json& v = (*views)[i];
    if (!r.object(v, at, "a view", kViewKeys)) {
      break;
    }
    TableViewUse use;
    if (auto id = r.text(v, at, "id", "the view's folder name")) {
      if (const auto problem = config::identifierProblem(*id)) {
        r.fail(at + ".id", *problem);
      }
      use.id = *id;
    }
    use.angleDeg = std::nan("");
    r.number(v, at, "angle_deg", config::Range::kAny, use.angleDeg);
    if (r.ok() && !(std::abs(use.angleDeg) <= kMaxAngleDeg)) {
      r.fail(at + ".angle_deg", text::printfText("required, within ±%.0f°", kMaxAngleDeg));
    }
    for (const auto& earlier : out) {
      if (r.ok() && earlier.id == use.id) {
        r.fail(at + ".id", "\"" + use.id + "\" is listed twice");
      }
    }
    out.push_back(std::move(use));
  }
  if (!r.ok()) {
    return std::unexpected(message(r.firstError().value_or(config::FieldError{})));
  }
  return out;
}

// The target's pose in the rig's world frame from its corners in one camera.
TableView placeTarget(const algo::Camera& camera, const Target& target,
                      const std::vector<std::array<double, 2>>& corners) {
  std::vector<cv::Point3d> object;
  for (const auto& p : innerCorners(target)) {
    object.emplace_back(p.x, p.y, 0.0);
  }
  std::vector<cv::Point2d> image;
  image.reserve(corners.size());
  for (const auto& c : corners) {
    image.emplace_back(c[0], c[1]);
  }
  const cv::Matx33d k(camera.K.data());
  const cv::Matx<double, 1, 5> dist(camera.dist.data());
  cv::Vec3d rvec;
  cv::Vec3d tvec;
  cv::solvePnP(object, image, k, dist, rvec, tvec, false, cv::SOLVEPNP_ITERATIVE);
  cv::Matx33d rotation;
  cv::Rodrigues(rvec, rotation);
  Eigen::Matrix3d rc;  // target → camera
  cv::cv2eigen(rotation, rc);
  const Eigen::Matrix3d cameraR =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(camera.R.data());
  const Eigen::Vector3d cameraT(camera.t[0], camera.t[1], camera.t[2]);
  TableView view;
  view.R = cameraR.transpose() * rc;
  view.t = cameraR.transpose() * (Eigen::Vector3d(tvec[0], tvec[1], tvec[2]) - cameraT);
  return view;
}

}  // namespace

std::expected<TableCalibration, std::string> calibrateTable(const algo::Rig& rig,
                                                            const fs::path& dir) {
  try {
    auto target = loadTarget(dir / "target.json");
    if (!target) {
      return std::unexpected(target.error());
    }
    const fs::path listFile = dir / "turntable.json";
    const auto text = config::readDocumentFile(listFile, kTableDocument);
    if (!text) {
      return std::unexpected(listFile.string() + ": " + message(text.error()));
    }
    auto uses = parseViews(*text);
    if (!uses) {
      return std::unexpected(listFile.string() + ": " + uses.error());
    }
    TableCalibration result;
    std::vector<TableView> views;
    for (auto& use : *uses) {
      for (const auto& camera : rig.cameras) {
        const fs::path file = dir / use.id / (camera.id + ".png");
        if (!fs::exists(file)) {
          continue;
        }
        auto image = sim::readPngRgb8(
            file, sim::PngSizeLimit::exactly(camera.width, camera.height, "camera " + camera.id));
        if (!image) {
          return std::unexpected(use.id + ": " + image.error() +
                                 ": capture this view again or remove it from turntable.json");
        }
        const auto corners = findTargetCorners(*target, image->view());
        if (corners.empty()) {
          continue;
        }
        TableView view = placeTarget(camera, *target, corners);
        view.name = use.id;
        view.angleDeg = use.angleDeg;
        views.push_back(view);
        use.camera = camera.id;
        break;
      }
      if (use.camera.empty()) {
        use.note =
            "target not found in any camera (not wholly in view, too dark or blurred): "
            "not used";
      }
    }
    auto fit = fitTurntableAxis(views, *target);
    if (!fit) {
      return std::unexpected(fit.error());
    }
    result.axis = *fit;
    result.views = std::move(*uses);
    return result;
  } catch (const std::exception& e) {
    return std::unexpected(std::string("cannot calibrate the turntable: ") + e.what());
  }
}

std::string tableReportText(const TableCalibration& calibration) {
  const AxisFit& a = calibration.axis;
  std::string out = text::printfText(
      "turntable axis: direction (%.4f, %.4f, %.4f) through (%.4f, %.4f, %.4f) m\n"
      "  corners against the first view turned about it: RMS %.3f mm; rotations %.3f° RMS;"
      " angle scale %.4f\n",
      a.direction.x(), a.direction.y(), a.direction.z(), a.point.x(), a.point.y(), a.point.z(),
      a.cornerRmsM * 1000.0, a.rotationRmsDeg, a.angleScale);
  std::size_t used = 0;
  for (const auto& view : calibration.views) {
    if (view.camera.empty()) {
      out += "  " + view.id + ": " + view.note + "\n";
    } else {
      out += text::printfText("  %s at %.2f°: %s (%.3f mm)\n", view.id.c_str(), view.angleDeg,
                              view.camera.c_str(), a.viewRmsM[used++] * 1000.0);
    }
  }
  return out;
}

}  // namespace smx::calib
