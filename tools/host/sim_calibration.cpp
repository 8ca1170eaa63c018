#include "sim_calibration.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <exception>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <variant>

#include "smx/algo/lens.hpp"
#include "smx/config/field_reader.hpp"
#include "smx/config/json_errors.hpp"
#include "smx/config/json_paths.hpp"
#include "smx/config/json_reader.hpp"
#include "smx/config/json_text.hpp"

namespace smx::host {
namespace {

namespace lens = algo::lens;
using sim::Mat3;
using sim::Vec3;

constexpr double kDeg = std::numbers::pi / 180.0;

// --- geometry ---

// SplitMix64: the same draws on every platform and standard library.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  double uniform(double lo, double hi) {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
    z ^= z >> 31U;
    return lo + (hi - lo) * (static_cast<double>(z >> 11U) * 0x1.0p-53);
  }

 private:
  std::uint64_t state_;
};

// Independent streams of one seed: poses and optics change independently.
constexpr std::uint64_t kPoseStream = 1;
constexpr std::uint64_t kOpticsStream = 2;
std::uint64_t streamSeed(std::uint64_t seed, std::uint64_t stream) {
  return seed * 0xD1B54A32D192ED03ULL + stream * 0x9E3779B97F4A7C15ULL;
}

lens::Point3 toPoint(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}
Vec3 toVec(const lens::Point3& p) {
  return {p[0], p[1], p[2]};
}

// The target point (x, y) in target coordinates.
Vec3 targetPoint(const TargetPose& pose, double x, double y) {
  return pose.R * Vec3(x, y, 0.0) + pose.t;
}

// Centre of the inner-corner grid, which is the centre of the sheet, in target coordinates.
Vec3 gridCentre(const calib::Target& target) {
  return {0.5 * (target.cols - 1) * target.squareM, 0.5 * (target.rows - 1) * target.squareM, 0.0};
}

// Sheet size, metres: the squares and the white margin round them.
double sheetWidthM(const calib::Target& target) {
  return (target.cols + 1 + 2 * kTargetMarginSquares) * target.squareM;
}
double sheetHeightM(const calib::Target& target) {
  return (target.rows + 1 + 2 * kTargetMarginSquares) * target.squareM;
}

bool inImage(const algo::DeviceModel& device, const Vec3& world, double marginPx) {
  const auto uv = lens::project(device, toPoint(world));
  return uv && uv->x >= marginPx && uv->x <= device.width - 1 - marginPx && uv->y >= marginPx &&
         uv->y <= device.height - 1 - marginPx;
}

}  // namespace

double workingDistanceM(const algo::Rig& rig) {
  const auto& camera = rig.cameras.front();
  double best = 0.8;
  double bestScore = std::numeric_limits<double>::infinity();
  for (int cm = 20; cm <= 500; ++cm) {
    const Vec3 point = toVec(lens::toWorld(camera, {0.0, 0.0, cm / 100.0}));
    double score = 0.0;
    for (const auto& p : rig.projectors) {
      const auto uv = lens::project(p, toPoint(point));
      score = uv ? std::max({score, std::abs(uv->x / (p.width - 1) - 0.5),
                             std::abs(uv->y / (p.height - 1) - 0.5)})
                 : std::numeric_limits<double>::infinity();
    }
    if (score < bestScore) {
      bestScore = score;
      best = cm / 100.0;
    }
  }
  return best;
}

namespace {

// Image area covered by the sheet in `camera`, as a fraction of the image (unclipped).
std::optional<double> sheetFill(const algo::DeviceModel& camera, const calib::Target& target,
                                const TargetPose& pose) {
  const double s = target.squareM;
  const double x0 = -(1 + kTargetMarginSquares) * s;
  const double y0 = x0;
  const double x1 = (target.cols + kTargetMarginSquares) * s;
  const double y1 = (target.rows + kTargetMarginSquares) * s;
  std::array<lens::Point2, 4> outline{};
  const std::array<std::array<double, 2>, 4> sheet = {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto uv = lens::project(camera, toPoint(targetPoint(pose, sheet[i][0], sheet[i][1])));
    if (!uv) {
      return std::nullopt;
    }
    outline[i] = *uv;
  }
  double twiceArea = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& a = outline[i];
    const auto& b = outline[(i + 1) % 4];
    twiceArea += a.x * b.y - b.x * a.y;
  }
  return std::abs(twiceArea) / 2.0 / (static_cast<double>(camera.width) * camera.height);
}

// Placement rules (drawTargetPoses()): how far inside an image a corner must be to count as in
// view, how obliquely the board may face a device, and how much of the image it fills.
constexpr double kCameraMarginPx = 4.0;
constexpr double kProjectorMarginPx = 8.0;
constexpr double kMaxObliquityDeg = 70.0;
constexpr double kMinFill = 0.2;
constexpr double kMaxFill = 0.7;
// In a partial pose some camera sees this share of the corners.
constexpr double kMinPartialShare = 0.3;
constexpr double kMaxPartialShare = 0.85;
constexpr int kPartialEvery = 6;
constexpr int kAttemptsPerPose = 200000;

bool acceptable(const algo::Rig& rig, const calib::Target& target, const TargetPose& pose,
                bool partial) {
  const auto fill = sheetFill(rig.cameras.front(), target, pose);
  if (!fill || *fill < kMinFill || *fill > kMaxFill) {
    return false;
  }
  const Vec3 front = -pose.R.col(2);  // z points into the board
  const Vec3 centre = targetPoint(pose, gridCentre(target).x(), gridCentre(target).y());
  const double minCos = std::cos(kMaxObliquityDeg * kDeg);
  const auto faces = [&](const algo::DeviceModel& d) {
    return front.dot((toVec(lens::centre(d)) - centre).normalized()) >= minCos;
  };
  if (!std::ranges::all_of(rig.cameras, faces) || !std::ranges::all_of(rig.projectors, faces)) {
    return false;
  }
  const auto corners = targetCorners(target, pose);
  bool someCameraPartial = false;
  for (const auto& camera : rig.cameras) {
    std::size_t seen = 0;
    for (const Vec3& c : corners) {
      if (!inImage(camera, c, kCameraMarginPx)) {
        continue;
      }
      ++seen;
      for (const auto& p : rig.projectors) {
        if (!inImage(p, c, kProjectorMarginPx)) {
          return false;  // every corner a camera sees is lit by every projector
        }
      }
    }
    const double share = static_cast<double>(seen) / static_cast<double>(corners.size());
    if (!partial && seen != corners.size()) {
      return false;
    }
    someCameraPartial =
        someCameraPartial || (share >= kMinPartialShare && share <= kMaxPartialShare);
  }
  return !partial || someCameraPartial;
}

// One candidate: the board centre at pixel (u, v) of the first camera and depth z along its axis,
// parallel to its image plane, then tilted about an axis in the board and turned in its plane.
std::optional<TargetPose> candidate(const algo::Rig& rig, const calib::Target& target, Rng& rng,
                                    double zLo, double zHi, bool partial) {
  const auto& camera = rig.cameras.front();
  const double spread = partial ? 0.6 : 0.2;  // of the image size, either side of its centre
  const double u = camera.width * rng.uniform(0.5 - spread, 0.5 + spread);
  const double v = camera.height * rng.uniform(0.5 - spread, 0.5 + spread);
  const double z = rng.uniform(zLo, zHi);
  const auto ray = lens::pixelRay(camera, {u, v});
  if (!ray) {
    return std::nullopt;
  }
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> cameraR(camera.R.data());
  const Vec3 direction = toVec(ray->direction);
  const double along = (cameraR * direction).z();
  if (!(along > 0.0)) {
    return std::nullopt;
  }
  const Vec3 centre = toVec(ray->origin) + (z / along) * direction;
  const double tiltAxis = rng.uniform(0.0, 360.0) * kDeg;
  const double tilt = rng.uniform(0.0, 45.0) * kDeg;
  const double turn = rng.uniform(-30.0, 30.0) * kDeg;
  const Mat3 inCamera =
      (Eigen::AngleAxisd(tilt, Vec3(std::cos(tiltAxis), std::sin(tiltAxis), 0.0)) *
       Eigen::AngleAxisd(turn, Vec3::UnitZ()))
          .toRotationMatrix();
  TargetPose pose;
  pose.R = cameraR.transpose() * inCamera;
  pose.t = centre - pose.R * gridCentre(target);
  return pose;
}

// --- scene ---

Vec3 grey(double level) {
  return Vec3::Constant(level);
}

nlohmann::ordered_json vec3Json(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

nlohmann::ordered_json mat3Json(const Mat3& m) {
  auto out = nlohmann::ordered_json::array();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      out.push_back(m(i, j));
    }
  }
  return out;
}

}  // namespace

std::string targetJson(const calib::Target& target) {
  nlohmann::ordered_json doc;
  doc["format"] = calib::kTargetFormat;
  doc["type"] = "checkerboard";
  doc["inner_corners"] = {target.cols, target.rows};
  doc["square_m"] = target.squareM;
  return doc.dump(2) + "\n";
}

std::vector<Vec3> targetCorners(const calib::Target& target, const TargetPose& pose) {
  std::vector<Vec3> out;
  out.reserve(static_cast<std::size_t>(target.cols) * static_cast<std::size_t>(target.rows));
  for (int row = 0; row < target.rows; ++row) {
    for (int col = 0; col < target.cols; ++col) {
      out.push_back(targetPoint(pose, col * target.squareM, row * target.squareM));
    }
  }
  return out;
}

std::expected<std::vector<TargetPose>, std::string> drawTargetPoses(const algo::Rig& rig,
                                                                    const calib::Target& target,
                                                                    int count, std::uint64_t seed) {
  if (rig.cameras.empty()) {
    return std::unexpected("the rig has no camera");
  }
  const auto& camera = rig.cameras.front();
  // Depths at which a board facing the camera fills 20–70 % of its image, kept near the working
  // distance where that range allows.
  const double focal = std::sqrt(camera.fx() * camera.fy());
  const double sheetArea = sheetWidthM(target) * sheetHeightM(target);
  const double pixels = static_cast<double>(camera.width) * camera.height;
  const double zNear = focal * std::sqrt(sheetArea / (kMaxFill * pixels));
  const double zFar = focal * std::sqrt(sheetArea / (kMinFill * pixels));
  const double working = workingDistanceM(rig);
  double zLo = std::max(zNear, 0.6 * working);
  double zHi = std::min(zFar, 1.4 * working);
  if (zLo >= zHi) {
    zLo = zNear;
    zHi = zFar;
  }
  Rng rng(streamSeed(seed, kPoseStream));
  std::vector<TargetPose> poses;
  for (int i = 0; i < count; ++i) {
    const bool partial = i % kPartialEvery == kPartialEvery - 1;
    std::optional<TargetPose> found;
    for (int attempt = 0; attempt < kAttemptsPerPose && !found; ++attempt) {
      found = candidate(rig, target, rng, zLo, zHi, partial);
      if (found && !acceptable(rig, target, *found, partial)) {
        found.reset();
      }
    }
    if (!found) {
      return std::unexpected(
          "cannot place the target (" + std::to_string(target.cols) + "x" +
          std::to_string(target.rows) + " corners, " + config::formatNumber(target.squareM) +
          " m squares) " + (partial ? "partly" : "wholly") +
          " in view of the cameras, lit by every projector and filling 20-70 % of " + camera.id +
          "'s image: the rig's views overlap too little for this target");
    }
    poses.push_back(*found);
  }
  return poses;
}

TargetSheet targetSheet(const calib::Target& target) {
  TargetSheet sheet;
  sheet.width = target.cols + 1 + 2 * kTargetMarginSquares;
  sheet.height = target.rows + 1 + 2 * kTargetMarginSquares;
  sheet.grey.assign(static_cast<std::size_t>(sheet.width) * static_cast<std::size_t>(sheet.height),
                    kPaperWhite);
  const auto margin = static_cast<std::size_t>(kTargetMarginSquares);
  // Square (i, j), i = 0 … cols, j = 0 … rows, is black when i + j is even: the square before the
  // first inner corner (top left) is black.
  for (int j = 0; j <= target.rows; ++j) {
    for (int i = 0; i <= target.cols; ++i) {
      if ((i + j) % 2 == 0) {
        const auto row = static_cast<std::size_t>(j) + margin;
        const auto col = static_cast<std::size_t>(i) + margin;
        sheet.grey[row * static_cast<std::size_t>(sheet.width) + col] = kPrintedBlack;
      }
    }
  }
  return sheet;
}

sim::Scene calibrationScene(const calib::Target& target, const std::vector<TargetPose>& poses,
                            int holdFrames, std::uint64_t seed, bool realism) {
  Rng rng(streamSeed(seed, kOpticsStream));
  sim::Scene scene;
  // Three samples per pixel side: square edges antialiased as a lens integrates them.
  scene.supersampling = 3;
  scene.lighting.ambient = grey(rng.uniform(0.35, 0.6));
  scene.lighting.projectorPower = 0.45;  // with the room light, white paper stays below full scale
  if (realism) {
    // The realism ranges of docs/simulator.md, as the eval's realism suite draws them.
    scene.lighting.projectorBlackLevel = rng.uniform(0.001, 0.02);
    scene.lighting.projectorGamma = rng.uniform(1.8, 2.4);
    scene.lighting.projectorDefocusSigmaPx = rng.uniform(0.0, 1.2);
    scene.camera.defocusSigmaPx = rng.uniform(0.0, 0.8);
    scene.camera.responseGamma = rng.uniform(1.0, 2.2);
    scene.camera.vignetting = rng.uniform(0.0, 0.4);
    const auto mosaic =
        std::min(static_cast<std::size_t>(rng.uniform(0.0, 5.0)), sim::kBayerPatterns.size() - 1);
    scene.camera.bayer = sim::kBayerPatterns[mosaic];
  }
  const TargetSheet sheet = targetSheet(target);
  sim::ImageTexture texture;
  texture.path = "target.png";
  texture.widthM = sheetWidthM(target);
  texture.heightM = sheetHeightM(target);
  texture.width = sheet.width;
  texture.height = sheet.height;
  for (const std::uint8_t g : sheet.grey) {
    // As the scene reader turns target.png's bytes into albedo.
    const float a = static_cast<float>(g) / 255.0F;
    texture.texels.push_back({a, a, a});
  }
  sim::Object board;
  board.name = "target";
  board.shape = sim::Plane{texture.widthM, texture.heightM};
  board.albedo.texture = std::move(texture);
  board.poseSequence.holdFrames = holdFrames;
  for (const auto& p : poses) {
    sim::Pose pose;
    pose.R = p.R;
    pose.t = p.t + p.R * gridCentre(target);  // the plane's centre is its local origin
    board.poseSequence.poses.push_back(pose);
  }
  scene.objects.push_back(std::move(board));
  return scene;
}

std::string calibrationSceneJson(const sim::Scene& scene) {
  using Json = nlohmann::ordered_json;
  const auto& l = scene.lighting;
  const auto& c = scene.camera;
  Json doc;
  doc["format"] = "stripemux-scene/1";
  doc["supersampling"] = scene.supersampling;
  doc["lighting"] = {{"ambient", vec3Json(l.ambient)},
                     {"projector_power", l.projectorPower},
                     {"inverse_square", l.inverseSquare},
                     {"reference_distance_m", l.referenceDistanceM},
                     {"projector_defocus_sigma_px", l.projectorDefocusSigmaPx},
                     {"projector_black_level", l.projectorBlackLevel},
                     {"projector_gamma", l.projectorGamma}};
  doc["camera_response"] = {{"crosstalk", mat3Json(c.crosstalk)},
                            {"gain", c.gain},
                            {"noise_sigma", vec3Json(c.noiseSigma)},
                            {"defocus_sigma_px", c.defocusSigmaPx},
                            {"response_gamma", c.responseGamma},
                            {"vignetting", c.vignetting},
                            {"bayer", c.bayer}};
  Json objects = Json::array();
  for (const auto& o : scene.objects) {
    const auto& plane = std::get<sim::Plane>(o.shape);
    const auto& texture = std::get<sim::ImageTexture>(o.albedo.texture);
    Json poses = Json::array();
    for (const auto& p : o.poseSequence.poses) {
      poses.push_back({{"R", mat3Json(p.R)}, {"t", vec3Json(p.t)}});
    }
    objects.push_back(
        {{"name", o.name},
         {"shape", {{"type", "plane"}, {"width_m", plane.widthM}, {"height_m", plane.heightM}}},
         {"pose_sequence", {{"hold_frames", o.poseSequence.holdFrames}, {"poses", poses}}},
         {"albedo",
          {{"texture",
            {{"path", texture.path},
             {"width_m", texture.widthM},
             {"height_m", texture.heightM}}}}}});
  }
  doc["objects"] = objects;
  return doc.dump(2) + "\n";
}

std::string targetPosesJson(const std::vector<TargetPose>& poses) {
  using Json = nlohmann::ordered_json;
  Json list = Json::array();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    list.push_back({{"pose", poseDirName(static_cast<int>(i))},
                    {"R", mat3Json(poses[i].R)},
                    {"t", vec3Json(poses[i].t)}});
  }
  Json doc;
  doc["format"] = kCalibrationTruthFormat;
  doc["poses"] = list;
  return doc.dump(2) + "\n";
}

std::string poseDirName(int index) {
  const std::string n = std::to_string(index);
  return "pose" + std::string(n.size() < 2 ? 2 - n.size() : 0, '0') + n;
}

}  // namespace smx::host
