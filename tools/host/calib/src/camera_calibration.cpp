#include "smx/calib/camera_calibration.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "smx/sim/png_io.hpp"

namespace smx::calib {
namespace {

// A pose whose corners fit this much worse than the median pose was blurred or moved during its
// exposure; below kSharpRmsPx every pose counts as sharp whatever the median.
constexpr double kOutlierRmsRatio = 3.0;
constexpr double kSharpRmsPx = 0.3;
// Two poses closer than this (board normal and centre) add nothing but weight.
constexpr double kSameTiltDeg = 2.0;
constexpr double kSameCentreM = 0.005;
// Focal length is told from distance only by tilted views: the normals must span this.
constexpr double kMinTiltSpreadDeg = 10.0;
// The corner refinement's half window, at most: beyond it more pixels cost time for little gain.
constexpr int kMaxCornerWindowPx = 20;

cv::Mat grey(const algo::ConstRgbView& image) {
  cv::Mat out(image.height(), image.width(), CV_8UC1);
  for (int y = 0; y < image.height(); ++y) {
    const auto row = image.row(y);
    for (int x = 0; x < image.width(); ++x) {
      const auto& p = row[static_cast<std::size_t>(x)];
      out.at<std::uint8_t>(y, x) =
          static_cast<std::uint8_t>((p.r * 77 + p.g * 150 + p.b * 29) >> 8);
    }
  }
  return out;
}

double sample(const cv::Mat& g, cv::Point2f p) {
  const int x = std::clamp(static_cast<int>(std::lround(p.x)), 0, g.cols - 1);
  const int y = std::clamp(static_cast<int>(std::lround(p.y)), 0, g.rows - 1);
  return g.at<std::uint8_t>(y, x);
}

// The target frame names the square between corners 0, 1, cols and cols + 1 dark; OpenCV orders
// the corners from whichever end it meets first, so a half turn is undone here (target.hpp).
void orderFromDarkCorner(std::vector<cv::Point2f>& corners, int cols, const cv::Mat& g) {
  const cv::Point2f c0 = corners[0];
  const cv::Point2f dx = corners[1] - c0;
  const cv::Point2f dy = corners[static_cast<std::size_t>(cols)] - c0;
  const double inside = sample(g, c0 + 0.5F * dx + 0.5F * dy);
  const double beside = sample(g, c0 + 0.5F * dx - 0.5F * dy);
  if (inside > beside) {
    std::ranges::reverse(corners);
  }
}

std::vector<cv::Point3f> objectPoints(const Target& target) {
  std::vector<cv::Point3f> out;
  for (const TargetPoint& p : innerCorners(target)) {
    out.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y), 0.0F);
  }
  return out;
}

cv::Mat toCv(const std::array<double, 9>& m) {
  cv::Mat out(3, 3, CV_64F);
  for (int i = 0; i < 9; ++i) {
    out.at<double>(i / 3, i % 3) = m[static_cast<std::size_t>(i)];
  }
  return out;
}

struct View {
  std::size_t pose = 0;
  std::vector<cv::Point2f> corners;
};

struct Intrinsics {
  cv::Mat K;
  cv::Mat dist;
  std::vector<cv::Mat> rvecs;
  std::vector<cv::Mat> tvecs;
  std::vector<double> perViewRms;
  std::array<double, 9> sd{};
  double rms = 0.0;
};

Intrinsics solveIntrinsics(const std::vector<View>& views, const Target& target,
                           const algo::Camera& nominal, int flags) {
  const std::vector<std::vector<cv::Point3f>> object(views.size(), objectPoints(target));
  std::vector<std::vector<cv::Point2f>> image;
  image.reserve(views.size());
  for (const View& v : views) {
    image.push_back(v.corners);
  }
  Intrinsics out;
  out.K = toCv(nominal.K);
  out.dist = cv::Mat(1, 5, CV_64F);
  for (int i = 0; i < 5; ++i) {
    out.dist.at<double>(0, i) = nominal.dist[static_cast<std::size_t>(i)];
  }
  cv::Mat sdIntrinsic;
  cv::Mat sdExtrinsic;
  cv::Mat perView;
  out.rms = cv::calibrateCamera(
      object, image, cv::Size(nominal.width, nominal.height), out.K, out.dist, out.rvecs, out.tvecs,
      sdIntrinsic, sdExtrinsic, perView, flags,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12));
  for (int i = 0; i < perView.rows; ++i) {
    out.perViewRms.push_back(perView.at<double>(i, 0));
  }
  for (int i = 0; i < 9 && i < sdIntrinsic.rows; ++i) {
    out.sd[static_cast<std::size_t>(i)] = sdIntrinsic.at<double>(i, 0);
  }
  return out;
}

Eigen::Matrix3d rotation(const cv::Mat& rvec) {
  cv::Mat matrix;
  cv::Rodrigues(rvec, matrix);
  Eigen::Matrix3d out;
  cv::cv2eigen(matrix, out);
  return out;
}

Eigen::Vector3d vector3(const cv::Mat& v) {
  return {v.at<double>(0), v.at<double>(1), v.at<double>(2)};
}

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 /
         std::numbers::pi;
}

std::string fixed2(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

// Drops poses that repeat an earlier one; fails when the rest do not tilt enough.
std::expected<void, std::string> checkPoseSpread(std::vector<View>& views, const Intrinsics& first,
                                                 const CaptureSet& set, const std::string& camera,
                                                 CameraFit& fit) {
  std::vector<Eigen::Vector3d> normals;
  std::vector<Eigen::Vector3d> centres;
  std::vector<View> kept;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const Eigen::Vector3d n = rotation(first.rvecs[i]).col(2);
    const Eigen::Vector3d c = vector3(first.tvecs[i]);
    bool repeat = false;
    for (std::size_t j = 0; j < normals.size() && !repeat; ++j) {
      if (angleDeg(n, normals[j]) < kSameTiltDeg && (c - centres[j]).norm() < kSameCentreM) {
        fit.poses[views[i].pose].note =
            "repeats " + set.poses[kept[j].pose].name + " (same tilt and place): not used";
        repeat = true;
      }
    }
    if (repeat) {
      continue;
    }
    normals.push_back(n);
    centres.push_back(c);
    kept.push_back(views[i]);
  }
  double spread = 0.0;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    for (std::size_t j = i + 1; j < normals.size(); ++j) {
      spread = std::max(spread, angleDeg(normals[i], normals[j]));
    }
  }
  if (spread < kMinTiltSpreadDeg) {
    return std::unexpected(camera + ": poses too similar: the target's tilts span only " +
                           fixed2(spread) + "°; capture it tilted 20–45° in several directions");
  }
  views = std::move(kept);
  return {};
}

}  // namespace

std::vector<std::array<double, 2>> findTargetCorners(const Target& target,
                                                     const algo::ConstRgbView& image) {
  const cv::Mat g = grey(image);
  std::vector<cv::Point2f> corners;
  const bool found =
      cv::findChessboardCorners(g, cv::Size(target.cols, target.rows), corners,
                                cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
  if (!found || corners.size() !=
                    static_cast<std::size_t>(target.cols) * static_cast<std::size_t>(target.rows)) {
    return {};
  }
  // The refinement window covers the four squares that meet at the corner out to half the
  // nearest corner spacing (along rows or columns) each side: their far edges, one spacing away,
  // stay out with room for blur and perspective, and every edge pixel inside averages the noise
  // down (with a quarter spacing the corners come out about a quarter noisier).
  double spacing = std::numeric_limits<double>::max();
  const auto cols = static_cast<std::size_t>(target.cols);
  for (int r = 0; r < target.rows; ++r) {
    for (int c = 0; c < target.cols; ++c) {
      const auto i = (static_cast<std::size_t>(r) * cols) + static_cast<std::size_t>(c);
      if (c + 1 < target.cols) {
        spacing = std::min<double>(spacing, cv::norm(corners[i + 1] - corners[i]));
      }
      if (r + 1 < target.rows) {
        spacing = std::min<double>(spacing, cv::norm(corners[i + cols] - corners[i]));
      }
    }
  }
  const int half = std::clamp(static_cast<int>(spacing / 2), 2, kMaxCornerWindowPx);
  cv::cornerSubPix(g, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-4));
  orderFromDarkCorner(corners, target.cols, g);
  std::vector<std::array<double, 2>> out;
  out.reserve(corners.size());
  for (const cv::Point2f& p : corners) {
    out.push_back({p.x, p.y});
  }
  return out;
}

std::expected<CamerasFit, std::string> calibrateCameras(const CaptureSet& set,
                                                        const algo::Rig& nominal) {
  CamerasFit result;
  result.targets.resize(set.poses.size());
  std::vector<std::vector<View>> viewsOf(nominal.cameras.size());
  std::vector<Intrinsics> intrinsics;
  for (std::size_t c = 0; c < nominal.cameras.size(); ++c) {
    const algo::Camera& cam = nominal.cameras[c];
    CameraFit fit;
    fit.camera = cam;
    std::vector<View>& views = viewsOf[c];
    for (std::size_t p = 0; p < set.poses.size(); ++p) {
      PoseUse use{.pose = set.poses[p].name, .used = false, .rmsPx = 0.0, .note = {}};
      const auto& file = set.poses[p].off[c];
      if (file.empty()) {
        use.note = "no " + cam.id + ".png";
      } else if (auto image = sim::readPngRgb8(
                     file, sim::PngSizeLimit::exactly(cam.width, cam.height, "camera " + cam.id));
                 !image) {
        return std::unexpected(set.poses[p].name + ": " + image.error() +
                               ": capture this pose again or remove its folder");
      } else if (auto corners = findTargetCorners(set.target, image->view()); corners.empty()) {
        use.note = "target not found (not wholly in view, too dark or blurred): not used";
      } else {
        View v{.pose = p, .corners = {}};
        for (const auto& q : corners) {
          v.corners.emplace_back(static_cast<float>(q[0]), static_cast<float>(q[1]));
        }
        views.push_back(std::move(v));
      }
      fit.poses.push_back(std::move(use));
    }
    const auto tooFew = [&] {
      std::string used;
      for (const View& v : views) {
        used += (used.empty() ? "" : ", ") + set.poses[v.pose].name;
      }
      std::string dropped;
      for (const PoseUse& use : fit.poses) {
        if (!use.note.empty()) {
          dropped += "; " + use.pose + ": " + use.note;
        }
      }
      return cam.id + ": the target is usable in " + std::to_string(views.size()) + " poses (" +
             (used.empty() ? "none" : used) + "), at least " + std::to_string(kMinPoses) +
             " are needed: capture more with the whole board sharp in " + cam.id + "'s view" +
             dropped;
    };
    if (static_cast<int>(views.size()) < kMinPoses) {
      return std::unexpected(tooFew());
    }
    int flags = cv::CALIB_USE_INTRINSIC_GUESS;
    if (cam.dist[4] == 0.0) {
      flags |= cv::CALIB_FIX_K3;  // a sixth-order term the corners of a few poses over-fit
      fit.fixedAtNominal.emplace_back("k3");
    }
    Intrinsics first = solveIntrinsics(views, set.target, cam, flags);
    if (auto spread = checkPoseSpread(views, first, set, cam.id, fit); !spread) {
      return std::unexpected(spread.error());
    }
    first = solveIntrinsics(views, set.target, cam, flags);
    // Blurred or moved poses: far worse than the median pose.
    std::vector<double> sorted = first.perViewRms;
    std::ranges::sort(sorted);
    const double median = sorted[sorted.size() / 2];
    std::vector<View> sharp;
    for (std::size_t i = 0; i < views.size(); ++i) {
      const double rms = first.perViewRms[i];
      if (rms > kSharpRmsPx && rms > kOutlierRmsRatio * median) {
        fit.poses[views[i].pose].note = "corners fit " + fixed2(rms) + " px against a median of " +
                                        fixed2(median) + " px (blurred or moved?): not used";
      } else {
        sharp.push_back(views[i]);
      }
    }
    if (static_cast<int>(sharp.size()) < kMinPoses) {
      views = sharp;
      return std::unexpected(tooFew());
    }
    views = std::move(sharp);
    Intrinsics solved = solveIntrinsics(views, set.target, cam, flags);
    for (int i = 0; i < 9; ++i) {
      fit.camera.K[static_cast<std::size_t>(i)] = solved.K.at<double>(i / 3, i % 3);
    }
    for (int i = 0; i < 5; ++i) {
      fit.camera.dist[static_cast<std::size_t>(i)] = solved.dist.at<double>(0, i);
    }
    fit.rmsPx = solved.rms;
    fit.sd = solved.sd;
    fit.corners.resize(set.poses.size());
    for (std::size_t i = 0; i < views.size(); ++i) {
      for (const cv::Point2f& q : views[i].corners) {
        fit.corners[views[i].pose].push_back({q.x, q.y});
      }
      fit.poses[views[i].pose].used = true;
      fit.poses[views[i].pose].rmsPx = solved.perViewRms[i];
    }
    intrinsics.push_back(std::move(solved));
    result.cameras.push_back(std::move(fit));
  }

  // The first camera is the world frame; the others from the poses they share with it.
  result.cameras[0].camera.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  result.cameras[0].camera.t = {0, 0, 0};
  const std::vector<cv::Point3f> object = objectPoints(set.target);
  for (std::size_t c = 1; c < result.cameras.size(); ++c) {
    std::vector<std::vector<cv::Point3f>> objects;
    std::vector<std::vector<cv::Point2f>> first;
    std::vector<std::vector<cv::Point2f>> other;
    for (const View& a : viewsOf[0]) {
      for (const View& b : viewsOf[c]) {
        if (a.pose == b.pose) {
          objects.push_back(object);
          first.push_back(a.corners);
          other.push_back(b.corners);
        }
      }
    }
    const std::string& id = result.cameras[c].camera.id;
    if (objects.size() < 2) {
      return std::unexpected(id + ": sees the target together with " + result.cameras[0].camera.id +
                             " in " + std::to_string(objects.size()) +
                             " poses; at least 2 are needed to place it: capture poses both see");
    }
    cv::Mat rot;
    cv::Mat trans;
    cv::Mat essential;
    cv::Mat fundamental;
    cv::stereoCalibrate(
        objects, first, other, intrinsics[0].K, intrinsics[0].dist, intrinsics[c].K,
        intrinsics[c].dist,
        cv::Size(result.cameras[c].camera.width, result.cameras[c].camera.height), rot, trans,
        essential, fundamental, cv::CALIB_FIX_INTRINSIC,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12));
    for (int i = 0; i < 9; ++i) {
      result.cameras[c].camera.R[static_cast<std::size_t>(i)] = rot.at<double>(i / 3, i % 3);
    }
    for (int i = 0; i < 3; ++i) {
      result.cameras[c].camera.t[static_cast<std::size_t>(i)] = trans.at<double>(i);
    }
  }

  // Each pose's target in the world, from the first camera that found it.
  for (std::size_t c = 0; c < result.cameras.size(); ++c) {
    const algo::Camera& cam = result.cameras[c].camera;
    const Eigen::Matrix3d camRot =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(cam.R.data());
    const Eigen::Vector3d tc(cam.t[0], cam.t[1], cam.t[2]);
    for (std::size_t i = 0; i < viewsOf[c].size(); ++i) {
      TargetPose& pose = result.targets[viewsOf[c][i].pose];
      if (pose.known) {
        continue;
      }
      // Target → camera, then camera → world.
      const Eigen::Matrix3d rot = rotation(intrinsics[c].rvecs[i]);
      const Eigen::Vector3d t = vector3(intrinsics[c].tvecs[i]);
      pose = {.known = true, .R = camRot.transpose() * rot, .t = camRot.transpose() * (t - tc)};
    }
  }
  return result;
}

}  // namespace smx::calib
