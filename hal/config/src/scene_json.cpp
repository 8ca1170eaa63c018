#include "smx/config/scene_json.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <variant>
#include <vector>

#include "scene_handheld.hpp"
#include "smx/config/field_reader.hpp"
#include "smx/config/json_errors.hpp"
#include "smx/config/json_keys.hpp"
#include "smx/config/json_paths.hpp"
#include "smx/config/json_reader.hpp"
#include "smx/config/json_text.hpp"
#include "smx/config/rotation_check.hpp"
#include "smx/sim/mesh_io.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::config {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using sim::Albedo;
using sim::Box;
using sim::CameraResponse;
using sim::CheckerTexture;
using sim::Cylinder;
using sim::ImageTexture;
using sim::Lighting;
using sim::Mat3;
using sim::Mesh;
using sim::Motion;
using sim::Object;
using sim::Plane;
using sim::Pose;
using sim::Scene;
using sim::Shape;
using sim::Sphere;
using sim::Vec3;

constexpr std::array<std::string_view, 7> kTopKeys = {
    "format", "supersampling", "lighting", "camera_response", "objects", "turntable", "handheld"};
constexpr std::array<std::string_view, 2> kTurntableKeys = {"axis", "pivot"};
constexpr std::array<std::string_view, 7> kLightingKeys = {"ambient",
                                                           "projector_power",
                                                           "inverse_square",
                                                           "reference_distance_m",
                                                           "projector_defocus_sigma_px",
                                                           "projector_black_level",
                                                           "projector_gamma"};
constexpr std::array<std::string_view, 9> kCameraKeys = {
    "crosstalk",  "gain",  "noise_sigma", "defocus_sigma_px", "response_gamma",
    "vignetting", "bayer", "exposure",    "exposure_samples"};
constexpr std::array<std::string_view, 7> kObjectKeys = {
    "name", "shape", "pose", "motion", "pose_sequence", "albedo", "on_turntable"};
constexpr std::array<std::string_view, 4> kPoseKeys = {"t", "rotation_deg", "R", "scale"};
constexpr std::array<std::string_view, 4> kMotionKeys = {"velocity_m_per_frame", "axis",
                                                         "angular_deg_per_frame", "pivot"};
constexpr std::array<std::string_view, 2> kPoseSequenceKeys = {"hold_frames", "poses"};
constexpr std::array<std::string_view, 5> kAlbedoKeys = {"rgb", "checker", "texture", "specular",
                                                         "shininess"};
// The albedo keys of which exactly one is given.
constexpr std::array<std::string_view, 3> kAlbedoKinds = {"rgb", "checker", "texture"};
constexpr std::array<std::string_view, 2> kCheckerKeys = {"square_m", "colours"};
constexpr std::array<std::string_view, 3> kTextureKeys = {"path", "width_m", "height_m"};

constexpr std::array<std::string_view, 3> kPlaneKeys = {"type", "width_m", "height_m"};
constexpr std::array<std::string_view, 2> kBoxKeys = {"type", "size_m"};
constexpr std::array<std::string_view, 2> kSphereKeys = {"type", "radius_m"};
constexpr std::array<std::string_view, 4> kCylinderKeys = {"type", "radius_m", "height_m",
                                                           "capped"};
constexpr std::array<std::string_view, 2> kMeshKeys = {"type", "path"};

// A pose held for up to a million frames (over 9 hours at 30 Hz); up to a thousand poses, far
// more than a calibration takes.
constexpr int kMaxHoldFrames = 1'000'000;
constexpr std::size_t kMaxSequencePoses = 1000;

// Time samples over one exposure: 16 steps keep a blur of a few pixels smooth.
constexpr int kMaxExposureSamples = 16;

struct ShapeType {
  std::string_view name;
  Keys keys;
};
constexpr std::array<ShapeType, 5> kShapeTypes = {{{"plane", kPlaneKeys},
                                                   {"box", kBoxKeys},
                                                   {"sphere", kSphereKeys},
                                                   {"cylinder", kCylinderKeys},
                                                   {"mesh", kMeshKeys}}};
// Words people reach for that are not the type names.
constexpr std::array<std::pair<std::string_view, std::string_view>, 10> kShapeSynonyms = {{
    {"cube", "box"},
    {"cuboid", "box"},
    {"rectangle", "plane"},
    {"quad", "plane"},
    {"wall", "plane"},
    {"ball", "sphere"},
    {"tube", "cylinder"},
    {"ply", "mesh"},
    {"obj", "mesh"},
    {"model", "mesh"},
}};

// A rig.json given as the scene is named as such.
constexpr std::array<FormatHint, 1> kOtherFormats = {
    {{"stripemux-rig/", " (this is a rig.json, not a scene)"}}};
// A scene.json is a few kB and 7 levels deep (objects[i].albedo.checker.colours[j]). The bounds
// keep a mistaken input (a mesh or an image given as the scene) from costing much.
constexpr DocumentSpec kSceneDocument = {.name = "scene.json",
                                         .format = kSceneFormat,
                                         .topKeys = kTopKeys,
                                         .maxBytes = std::size_t{1} << 20U,
                                         .sizeNote = " (meshes and textures go in their own files)",
                                         .nestingNeeded = 7,
                                         .maxNesting = 16,
                                         .otherFormats = kOtherFormats};

// --- Reading scene values ---

// The generic reads, plus the scene's vectors and matrices (Eigen).
class Reader : public FieldReader {
 public:
  [[nodiscard]] std::unexpected<SceneError> error() const {
    const auto e = firstError().value_or(FieldError{});
    return std::unexpected(SceneError{{}, e.field, e.problem});
  }

  void vec3(const Json& obj, const std::string& path, std::string_view key, std::string_view what,
            Range range, Vec3& out) {
    if (const Json* v = find(obj, key); v != nullptr) {
      if (const auto a = numbers<3>(*v, member(path, key), what, range)) {
        out = Vec3((*a)[0], (*a)[1], (*a)[2]);
      }
    }
  }

  void mat3(const Json& obj, const std::string& path, std::string_view key, std::string_view what,
            Mat3& out) {
    if (const Json* v = find(obj, key); v != nullptr) {
      if (const auto a = numbers<9>(*v, member(path, key), what, Range::kAny)) {
        out = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(a->data());
      }
    }
  }
};

// sin and cos of an angle in degrees; exact at multiples of 90° so that quarter turns give
// rotation matrices of exact zeros and ones.
std::pair<double, double> sinCosDeg(double deg) {
  const double reduced = std::remainder(deg, 360.0);  // exact, in [-180, 180]
  const double quarters = reduced / 90.0;
  if (quarters == std::round(quarters)) {
    switch (static_cast<int>(quarters)) {
      case 0:
        return {0.0, 1.0};
      case 1:
        return {1.0, 0.0};
      case -1:
        return {-1.0, 0.0};
      default:
        return {0.0, -1.0};  // ±180°
    }
  }
  const double rad = reduced * std::numbers::pi / 180.0;
  return {std::sin(rad), std::cos(rad)};
}

// R = Rz(rz) · Ry(ry) · Rx(rx): rotate about x first, then y, then z (fixed axes), right-handed.
Mat3 rotationFromDegrees(const Vec3& deg) {
  const auto [sx, cx] = sinCosDeg(deg.x());
  const auto [sy, cy] = sinCosDeg(deg.y());
  const auto [sz, cz] = sinCosDeg(deg.z());
  Mat3 rx;
  rx << 1, 0, 0, 0, cx, -sx, 0, sx, cx;
  Mat3 ry;
  ry << cy, 0, sy, 0, 1, 0, -sy, 0, cy;
  Mat3 rz;
  rz << cz, -sz, 0, sz, cz, 0, 0, 0, 1;
  return rz * ry * rx;
}

void readLighting(Reader& r, const Json& doc, Lighting& out) {
  const std::string path = "lighting";
  const Json* v = r.find(doc, path);
  if (v == nullptr || !r.object(*v, path, "the lighting settings", kLightingKeys)) {
    return;
  }
  r.vec3(*v, path, "ambient", "r, g, b, each at least 0", Range::kAny, out.ambient);
  r.number(*v, path, "projector_power", Range::kAny, out.projectorPower);
  r.boolean(*v, path, "inverse_square", out.inverseSquare);
  r.number(*v, path, "reference_distance_m", Range::kAny, out.referenceDistanceM);
  r.number(*v, path, "projector_defocus_sigma_px", Range::kAny, out.projectorDefocusSigmaPx);
  r.number(*v, path, "projector_black_level", Range::kAny, out.projectorBlackLevel);
  r.number(*v, path, "projector_gamma", Range::kAny, out.projectorGamma);
}

std::string bayerNames() {
  std::string out;
  for (const auto name : sim::kBayerPatterns) {
    out += (out.empty() ? "" : ", ") + jsonQuote(name);
  }
  return out;
}

void readCameraResponse(Reader& r, const Json& doc, CameraResponse& out) {
  const std::string path = "camera_response";
  const Json* v = r.find(doc, path);
  if (v == nullptr || !r.object(*v, path, "the camera response settings", kCameraKeys)) {
    return;
  }
  r.mat3(*v, path, "crosstalk", "row-major 3x3 matrix, camera RGB = crosstalk * scene RGB",
         out.crosstalk);
  r.number(*v, path, "gain", Range::kAny, out.gain);
  r.vec3(*v, path, "noise_sigma", "r, g, b in grey levels", Range::kAny, out.noiseSigma);
  r.number(*v, path, "defocus_sigma_px", Range::kAny, out.defocusSigmaPx);
  r.number(*v, path, "response_gamma", Range::kAny, out.responseGamma);
  r.number(*v, path, "vignetting", Range::kAny, out.vignetting);
  if (const Json* bayer = r.find(*v, "bayer"); bayer != nullptr) {
    if (bayer->is_string()) {
      out.bayer = bayer->get<std::string>();
    } else {
      r.fail(member(path, "bayer"),
             "must be a string, one of " + bayerNames() + "; got " + describe(*bayer));
    }
  }
  r.number(*v, path, "exposure", Range::kAny, out.exposure);
  r.integer(*v, path, "exposure_samples", 1, kMaxExposureSamples, "time samples over the exposure",
            out.exposureSamples);
}

std::string shapeTypeNames() {
  std::string out;
  for (const auto& t : kShapeTypes) {
    out += (out.empty() ? "" : ", ") + std::string(t.name);
  }
  return out;
}

// "radius_m is for sphere and cylinder shapes" when another shape type has the key.
std::string otherShapeHint(std::string_view key, std::string_view type) {
  std::vector<std::string_view> owners;
  for (const auto& t : kShapeTypes) {
    if (std::find(t.keys.begin(), t.keys.end(), key) != t.keys.end()) {
      owners.push_back(t.name);
    }
  }
  if (owners.empty()) {
    return {};
  }
  std::string list;
  for (std::size_t i = 0; i < owners.size(); ++i) {
    list += (i == 0 ? "" : (i + 1 == owners.size() ? " and " : ", ")) + std::string(owners[i]);
  }
  return std::string(key) + " is for " + list + " shapes, not for a " + std::string(type);
}

const ShapeType* readShapeType(Reader& r, const Json& shape, const std::string& path) {
  const std::string at = member(path, "type");
  const auto it = shape.find("type");
  if (it == shape.end()) {
    r.fail(at, "required field is missing; one of " + shapeTypeNames());
    return nullptr;
  }
  if (!it->is_string()) {
    r.fail(at, "must be a string, one of " + shapeTypeNames() + "; got " + describe(*it));
    return nullptr;
  }
  const auto& name = it->get_ref<const std::string&>();
  for (const auto& t : kShapeTypes) {
    if (t.name == name) {
      return &t;
    }
  }
  std::string_view guess;
  for (const auto& [word, type] : kShapeSynonyms) {
    if (equalIgnoringCase(word, name)) {
      guess = type;
    }
  }
  if (guess.empty()) {
    std::array<std::string_view, kShapeTypes.size()> names{};
    std::transform(kShapeTypes.begin(), kShapeTypes.end(), names.begin(),
                   [](const ShapeType& t) { return t.name; });
    guess = closestWord(name, names);
  }
  r.fail(at, "unknown shape type " + jsonQuote(name) +
                 (guess.empty() ? "" : " (did you mean " + jsonQuote(guess) + "?)") +
                 "; types: " + shapeTypeNames());
  return nullptr;
}

// Shape parameters; a mesh keeps the path as written until the object's files are loaded.
void readShape(Reader& r, const Json& obj, const std::string& objectPath, Shape& out) {
  const std::string path = member(objectPath, "shape");
  const Json* v = r.find(obj, "shape");
  if (v == nullptr) {
    r.fail(path, R"(required field is missing; e.g. "shape": {"type": "sphere", "radius_m": 0.1})");
    return;
  }
  if (!v->is_object()) {
    r.fail(path, "must be an object {\"type\": ...}, got " + describe(*v));
    return;
  }
  const ShapeType* type = readShapeType(r, *v, path);
  if (type == nullptr) {
    return;
  }
  if (const auto key = unknownKey(*v, type->keys)) {
    r.fail(path, unknownKeyProblem(*key, type->keys, otherShapeHint(*key, type->name)));
    return;
  }
  if (type->name == "plane") {
    Plane plane;
    r.number(*v, path, "width_m", Range::kAny, plane.widthM);
    r.number(*v, path, "height_m", Range::kAny, plane.heightM);
    out = plane;
  } else if (type->name == "box") {
    Box box;
    r.vec3(*v, path, "size_m", "x, y, z edge lengths in metres, each positive", Range::kAny,
           box.sizeM);
    out = box;
  } else if (type->name == "sphere") {
    Sphere sphere;
    r.number(*v, path, "radius_m", Range::kAny, sphere.radiusM);
    out = sphere;
  } else if (type->name == "cylinder") {
    Cylinder cylinder;
    r.number(*v, path, "radius_m", Range::kAny, cylinder.radiusM);
    r.number(*v, path, "height_m", Range::kAny, cylinder.heightM);
    r.boolean(*v, path, "capped", cylinder.capped);
    out = cylinder;
  } else {
    Mesh mesh;
    mesh.path = r.text(*v, path, "path", "the PLY or OBJ file, e.g. \"meshes/bun_zipper.ply\"")
                    .value_or(std::string());
    out = std::move(mesh);
  }
}

// One pose object {"t", "R" or "rotation_deg", "scale"} at `path`.
void readPoseValue(Reader& r, const Json* v, const std::string& path, Pose& out) {
  if (v == nullptr || !r.object(*v, path, "the object's pose", kPoseKeys)) {
    return;
  }
  r.vec3(*v, path, "t", "x, y, z in metres", Range::kAny, out.t);
  if (v->contains("R") && v->contains("rotation_deg")) {
    r.fail(path, R"(give the rotation as "R" or as "rotation_deg", not both)");
    return;
  }
  if (v->contains("rotation_deg")) {
    Vec3 degrees = Vec3::Zero();
    r.vec3(*v, path, "rotation_deg", "rx, ry, rz in degrees, R = Rz * Ry * Rx", Range::kAny,
           degrees);
    out.R = rotationFromDegrees(degrees);
  } else if (v->contains("R")) {
    r.mat3(*v, path, "R", "row-major 3x3 rotation, object to world", out.R);
  }
  r.number(*v, path, "scale", Range::kAny, out.scale);
}

void readPose(Reader& r, const Json& obj, const std::string& objectPath, Pose& out) {
  readPoseValue(r, r.find(obj, "pose"), member(objectPath, "pose"), out);
}

// Types and lengths only; the values are checked by checkPoseSequence().
void readPoseSequence(Reader& r, const Json& obj, const std::string& objectPath,
                      sim::PoseSequence& out) {
  const std::string path = member(objectPath, "pose_sequence");
  const Json* v = r.find(obj, "pose_sequence");
  if (v == nullptr) {
    return;
  }
  if (obj.contains("pose") || obj.contains("motion")) {
    r.fail(path, R"(an object with a pose_sequence has no "pose" or "motion": the sequence )"
                 "gives its poses");
    return;
  }
  if (!r.object(*v, path, R"(a target placed by hand {"hold_frames", "poses"})",
                kPoseSequenceKeys)) {
    return;
  }
  r.integer(*v, path, "hold_frames", 1, kMaxHoldFrames, "frames each pose is held", out.holdFrames);
  const std::string at = member(path, "poses");
  const Json* poses = r.find(*v, "poses");
  if (poses == nullptr) {
    r.fail(at, R"(required field is missing; e.g. "poses": [{"t": [0, 0, 0.8]}])");
    return;
  }
  if (!poses->is_array() || poses->empty() || poses->size() > kMaxSequencePoses) {
    r.fail(at, "must be an array of 1 to " + std::to_string(kMaxSequencePoses) + " poses, got " +
                   describe(*poses));
    return;
  }
  out.poses.assign(poses->size(), Pose{});
  for (std::size_t i = 0; i < poses->size() && r.ok(); ++i) {
    readPoseValue(r, &(*poses)[i], element(at, i), out.poses[i]);
  }
}

void readMotion(Reader& r, const Json& obj, const std::string& objectPath, Motion& out) {
  const std::string path = member(objectPath, "motion");
  const Json* v = r.find(obj, "motion");
  if (v == nullptr || !r.object(*v, path, "the object's motion per frame", kMotionKeys)) {
    return;
  }
  r.vec3(*v, path, "velocity_m_per_frame", "x, y, z in metres per frame", Range::kAny,
         out.velocityMPerFrame);
  r.vec3(*v, path, "axis", "x, y, z direction of the rotation axis", Range::kAny, out.axis);
  r.number(*v, path, "angular_deg_per_frame", Range::kAny, out.angularDegPerFrame);
  r.vec3(*v, path, "pivot", "x, y, z of a point on the axis, metres", Range::kAny, out.pivot);
}

void readTurntable(Reader& r, const Json& doc, Scene& scene) {
  const Json* v = r.find(doc, "turntable");
  if (v == nullptr ||
      !r.object(*v, "turntable", "the turntable's axis and pivot in the world frame",
                kTurntableKeys)) {
    return;
  }
  sim::TurntableMount& mount = scene.turntable.emplace();
  r.vec3(*v, "turntable", "axis", "x, y, z direction of the turntable's axis", Range::kAny,
         mount.axis);
  r.vec3(*v, "turntable", "pivot", "x, y, z of a point on the axis, metres", Range::kAny,
         mount.pivot);
}

void checkTurntable(Reader& r, const Scene& scene) {
  if (!scene.turntable) {
    for (std::size_t i = 0; i < scene.objects.size() && r.ok(); ++i) {
      if (scene.objects[i].onTurntable) {
        r.fail(member(element("objects", i), "on_turntable"),
               "the scene has no \"turntable\" for the object to stand on");
      }
    }
    return;
  }
  r.checkEach(scene.turntable->axis, "turntable.axis", Range::kAny);
  if (r.ok() && !(scene.turntable->axis.stableNorm() > 0)) {
    r.fail("turntable.axis",
           "must not be the zero vector; it is the direction of the axis, e.g. "
           "[0, -1, 0] (up)");
  }
  r.checkEach(scene.turntable->pivot, "turntable.pivot", Range::kAny);
}

void readChecker(Reader& r, const Json& v, const std::string& path, CheckerTexture& out) {
  if (!r.object(v, path, R"(a checkerboard {"square_m", "colours"})", kCheckerKeys)) {
    return;
  }
  r.number(v, path, "square_m", Range::kAny, out.squareM);
  const Json* colours = r.find(v, "colours");
  if (colours == nullptr) {
    return;
  }
  const std::string at = member(path, "colours");
  if (!colours->is_array() || colours->empty()) {
    r.fail(at, "must be an array of at least one [r, g, b] colour, got " + describe(*colours));
    return;
  }
  out.colours.clear();
  for (std::size_t i = 0; i < colours->size(); ++i) {
    const auto rgb =
        r.numbers<3>((*colours)[i], element(at, i), "r, g, b, each 0 to 1", Range::kAny);
    if (!rgb) {
      return;
    }
    out.colours.emplace_back((*rgb)[0], (*rgb)[1], (*rgb)[2]);
  }
}

void readTexture(Reader& r, const Json& v, const std::string& path, ImageTexture& out) {
  if (!r.object(v, path, R"(an image texture {"path", "width_m", "height_m"})", kTextureKeys)) {
    return;
  }
  out.path =
      r.text(v, path, "path", "the PNG file, e.g. \"textures/poster.png\"").value_or(std::string());
  r.number(v, path, "width_m", Range::kAny, out.widthM);
  r.number(v, path, "height_m", Range::kAny, out.heightM);
}

void readAlbedo(Reader& r, const Json& obj, const std::string& objectPath, Albedo& out) {
  const std::string path = member(objectPath, "albedo");
  const Json* v = r.find(obj, "albedo");
  if (v == nullptr || !r.object(*v, path, "the object's albedo", kAlbedoKeys)) {
    return;
  }
  std::vector<std::string_view> given;
  r.number(*v, path, "specular", Range::kAny, out.specular);
  r.number(*v, path, "shininess", Range::kAny, out.shininess);
  for (const auto key : kAlbedoKinds) {
    if (v->contains(key)) {
      given.push_back(key);
    }
  }
  if (given.size() != 1) {
    std::string got;
    for (std::size_t i = 0; i < given.size(); ++i) {
      got += (i == 0 ? ", got " : (i + 1 == given.size() ? " and " : ", ")) + jsonQuote(given[i]);
    }
    r.fail(path, R"(needs exactly one of "rgb", "checker" or "texture")" + got);
    return;
  }
  if (given[0] == "rgb") {
    r.vec3(*v, path, "rgb", "r, g, b, each 0 to 1", Range::kAny, out.rgb);
  } else if (given[0] == "checker") {
    CheckerTexture checker;
    readChecker(r, v->at("checker"), member(path, "checker"), checker);
    out.texture = std::move(checker);
  } else {
    ImageTexture texture;
    readTexture(r, v->at("texture"), member(path, "texture"), texture);
    out.texture = std::move(texture);
  }
}

// --- value rules, shared by parseScene() and validateScene() ---
//
// The reading above checks types and array lengths; these rules check values, once per part,
// right after the part is read, so that a problem is still reported in file order (within a
// part, types first). A scene built in memory passes through the same rules.

void checkSupersampling(Reader& r, int supersampling) {
  r.check(supersampling, "supersampling", 1, sim::kMaxSceneSupersampling, "samples per pixel side");
}

// lo ≤ d ≤ hi, the physical range of a setting.
void checkBetween(Reader& r, double d, const std::string& path, double lo, double hi) {
  if (r.check(d, path, Range::kAny) && (d < lo || d > hi)) {
    r.fail(path, "must be from " + formatNumber(lo) + " to " + formatNumber(hi) + ", got " +
                     formatNumber(d));
  }
}

void checkLighting(Reader& r, const Lighting& l) {
  const std::string path = "lighting";
  // Above 1 the ambient alone saturates the camera: sunlight on a scanner, which the eval sweeps.
  r.checkEach(l.ambient, member(path, "ambient"), Range::kNonNegative);
  r.check(l.projectorPower, member(path, "projector_power"), Range::kPositive);
  r.check(l.referenceDistanceM, member(path, "reference_distance_m"), Range::kPositive);
  r.check(l.projectorDefocusSigmaPx, member(path, "projector_defocus_sigma_px"),
          Range::kNonNegative);
  // 0.2 is a 5:1 contrast, a projector washed out by room light; beyond it no stripe survives.
  checkBetween(r, l.projectorBlackLevel, member(path, "projector_black_level"), 0.0, 0.2);
  // Displays run from linear (1) to a CRT-like 2.2–2.6; 3 covers the steepest.
  checkBetween(r, l.projectorGamma, member(path, "projector_gamma"), 1.0, 3.0);
}

void checkCameraResponse(Reader& r, const CameraResponse& c) {
  const std::string path = "camera_response";
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> crosstalk = c.crosstalk;
  r.checkEach(std::span<const double>(crosstalk.data(), 9), member(path, "crosstalk"), Range::kAny);
  r.check(c.gain, member(path, "gain"), Range::kPositive);
  r.checkEach(c.noiseSigma, member(path, "noise_sigma"), Range::kNonNegative);
  r.check(c.defocusSigmaPx, member(path, "defocus_sigma_px"), Range::kNonNegative);
  checkBetween(r, c.responseGamma, member(path, "response_gamma"), 1.0, 3.0);
  // 0.8 is an 80 % loss at the corner, a cheap wide-angle lens wide open.
  checkBetween(r, c.vignetting, member(path, "vignetting"), 0.0, 0.8);
  if (r.ok() && std::ranges::find(sim::kBayerPatterns, c.bayer) == sim::kBayerPatterns.end()) {
    const std::string_view guess = closestWord(c.bayer, sim::kBayerPatterns);
    r.fail(member(path, "bayer"),
           "unknown pattern " + jsonQuote(c.bayer) +
               (guess.empty() ? "" : " (did you mean " + jsonQuote(guess) + "?)") +
               "; patterns: " + bayerNames());
  }
  checkBetween(r, c.exposure, member(path, "exposure"), 0.0, 1.0);
  r.check(c.exposureSamples, member(path, "exposure_samples"), 1, kMaxExposureSamples,
          "time samples over the exposure");
}

void checkShape(Reader& r, const Shape& shape, const std::string& path) {
  if (const auto* p = std::get_if<Plane>(&shape)) {
    r.check(p->widthM, member(path, "width_m"), Range::kPositive);
    r.check(p->heightM, member(path, "height_m"), Range::kPositive);
  } else if (const auto* b = std::get_if<Box>(&shape)) {
    r.checkEach(b->sizeM, member(path, "size_m"), Range::kPositive);
  } else if (const auto* sphere = std::get_if<Sphere>(&shape)) {
    r.check(sphere->radiusM, member(path, "radius_m"), Range::kPositive);
  } else if (const auto* c = std::get_if<Cylinder>(&shape)) {
    r.check(c->radiusM, member(path, "radius_m"), Range::kPositive);
    r.check(c->heightM, member(path, "height_m"), Range::kPositive);
  } else if (std::get<Mesh>(shape).path.empty()) {
    r.fail(member(path, "path"), "must not be empty");
  }
}

void checkPose(Reader& r, const Pose& pose, const std::string& path) {
  r.checkEach(pose.t, member(path, "t"), Range::kAny);
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> rotation = pose.R;
  r.checkEach(std::span<const double>(rotation.data(), 9), member(path, "R"), Range::kAny);
  if (auto problem =
          r.ok() ? rotationProblem(std::span<const double, 9>(rotation.data(), 9)) : std::nullopt) {
    r.fail(member(path, "R"), std::move(*problem));
  }
  r.check(pose.scale, member(path, "scale"), Range::kPositive);
}

void checkMotion(Reader& r, const Motion& m, const std::string& path) {
  r.checkEach(m.velocityMPerFrame, member(path, "velocity_m_per_frame"), Range::kAny);
  r.checkEach(m.axis, member(path, "axis"), Range::kAny);
  // stableNorm: [1e300, 0, 0] is a fine direction even though its squared norm overflows.
  if (r.ok() && !(m.axis.stableNorm() > 0)) {
    r.fail(member(path, "axis"),
           "must not be the zero vector; it is the direction of the rotation axis, e.g. [0, 1, 0]");
  }
  r.check(m.angularDegPerFrame, member(path, "angular_deg_per_frame"), Range::kAny);
  r.checkEach(m.pivot, member(path, "pivot"), Range::kAny);
}

void checkPoseSequence(Reader& r, const sim::PoseSequence& s, const Motion& m,
                       const std::string& path) {
  if (s.poses.empty()) {
    return;
  }
  r.check(s.holdFrames, member(path, "hold_frames"), 1, kMaxHoldFrames, "frames each pose is held");
  if (r.ok() && s.poses.size() > kMaxSequencePoses) {
    r.fail(member(path, "poses"), "has " + std::to_string(s.poses.size()) + " poses; at most " +
                                      std::to_string(kMaxSequencePoses));
  }
  for (std::size_t i = 0; i < s.poses.size() && r.ok(); ++i) {
    checkPose(r, s.poses[i], element(member(path, "poses"), i));
  }
  if (r.ok() && (!m.velocityMPerFrame.isZero(0.0) || m.angularDegPerFrame != 0.0)) {
    r.fail(path, "an object with a pose_sequence has no motion");
  }
}

void checkAlbedo(Reader& r, const Albedo& a, const std::string& path) {
  if (const auto* c = std::get_if<CheckerTexture>(&a.texture)) {
    const std::string at = member(path, "checker");
    r.check(c->squareM, member(at, "square_m"), Range::kPositive);
    if (r.ok() && c->colours.empty()) {
      r.fail(member(at, "colours"), "must be an array of at least one [r, g, b] colour, got []");
    }
    for (std::size_t i = 0; i < c->colours.size(); ++i) {
      r.checkEach(c->colours[i], element(member(at, "colours"), i), Range::kFraction);
    }
  } else if (const auto* t = std::get_if<ImageTexture>(&a.texture)) {
    const std::string at = member(path, "texture");
    if (r.ok() && t->path.empty()) {
      r.fail(member(at, "path"), "must not be empty");
    }
    r.check(t->widthM, member(at, "width_m"), Range::kPositive);
    r.check(t->heightM, member(at, "height_m"), Range::kPositive);
  } else {
    r.checkEach(a.rgb, member(path, "rgb"), Range::kFraction);
  }
  r.check(a.specular, member(path, "specular"), Range::kFraction);
  checkBetween(r, a.shininess, member(path, "shininess"), 1.0, 10000.0);
}

// An object's values, in the order its parts are read.
void checkObject(Reader& r, const Object& o, const std::string& path) {
  checkShape(r, o.shape, member(path, "shape"));
  checkPose(r, o.pose, member(path, "pose"));
  checkMotion(r, o.motion, member(path, "motion"));
  checkPoseSequence(r, o.poseSequence, o.motion, member(path, "pose_sequence"));
  checkAlbedo(r, o.albedo, member(path, "albedo"));
}

// What the object's files hold (the loaders promise it; a scene built in memory may not).
void checkLoaded(Reader& r, const Object& o, const std::string& path) {
  if (const auto* mesh = std::get_if<Mesh>(&o.shape); mesh != nullptr && r.ok()) {
    const std::string at = member(member(path, "shape"), "path");
    const std::string name = "mesh " + jsonQuote(mesh->path);
    if (mesh->triangles.empty() || mesh->vertices.empty()) {
      r.fail(at, name + " is empty (no triangles)");
    } else if (mesh->vertices.size() > std::numeric_limits<std::uint32_t>::max()) {
      r.fail(at, name + " has more vertices than 32-bit indices can name");
    } else if (!std::ranges::all_of(mesh->vertices, [](const auto& v) { return v.allFinite(); })) {
      r.fail(at, name + " has a vertex that is not finite");
    }
    for (std::size_t i = 0; i < mesh->triangles.size() && r.ok(); ++i) {
      for (const std::uint32_t k : mesh->triangles[i]) {
        if (k >= mesh->vertices.size()) {
          r.fail(at, name + ": triangle " + std::to_string(i) + " names vertex " +
                         std::to_string(k) + " of " + std::to_string(mesh->vertices.size()));
        }
      }
    }
  }
  if (const auto* t = std::get_if<ImageTexture>(&o.albedo.texture); t != nullptr && r.ok()) {
    if (t->width <= 0 || t->height <= 0 ||
        t->texels.size() !=
            static_cast<std::size_t>(t->width) * static_cast<std::size_t>(t->height)) {
      r.fail(member(member(member(path, "albedo"), "texture"), "path"),
             "texture " + jsonQuote(t->path) + " is not loaded (no texels)");
    }
  }
}

void checkObjectCount(Reader& r, std::size_t n) {
  if (n == 0) {
    r.fail("objects", "at least one object is required, got none");
  }
}

// Object names are unique; an unnamed object is "object<N>" after its index.
class NameRegistry {
 public:
  void add(Reader& r, const std::string& name, const std::string& path, bool given) {
    const auto [it, inserted] = owners_.emplace(name, Owner{path, given});
    if (inserted) {
      return;
    }
    const std::string owner =
        it->second.given ? it->second.path : "the unnamed " + it->second.path + " (its default)";
    if (given) {
      r.fail(member(path, "name"), jsonQuote(name) + " is already the name of " + owner +
                                       "; object names must be unique");
    } else {
      r.fail(path, "has no name, and its default name " + jsonQuote(name) +
                       " is already the name of " + owner + "; give one of them another name");
    }
  }

 private:
  struct Owner {
    std::string path;
    bool given;
  };
  std::map<std::string, Owner, std::less<>> owners_;
};

// Loads what the object's shape and albedo name; the same mesh file is read once per scene.
class FileLoader {
 public:
  explicit FileLoader(fs::path baseDir) : baseDir_(std::move(baseDir)) {}

  void load(Reader& r, const std::string& objectPath, Object& object) {
    if (auto* mesh = std::get_if<Mesh>(&object.shape); mesh != nullptr && r.ok()) {
      loadMeshFile(r, member(member(objectPath, "shape"), "path"), *mesh);
    }
    if (auto* texture = std::get_if<ImageTexture>(&object.albedo.texture);
        texture != nullptr && r.ok()) {
      loadTexture(r, member(member(member(objectPath, "albedo"), "texture"), "path"), *texture);
    }
  }

 private:
  [[nodiscard]] fs::path resolve(const std::string& path) const {
    return (baseDir_ / path).lexically_normal();
  }

  void loadMeshFile(Reader& r, const std::string& field, Mesh& mesh) {
    const fs::path file = resolve(mesh.path);
    auto it = meshes_.find(file);
    if (it == meshes_.end()) {
      auto loaded = sim::loadMesh(file);
      if (!loaded) {
        r.fail(field, "cannot load mesh " + loaded.error().message());
        return;
      }
      it = meshes_.emplace(file, std::move(*loaded)).first;
    }
    mesh = it->second;
  }

  void loadTexture(Reader& r, const std::string& field, ImageTexture& texture) const {
    const fs::path file = resolve(texture.path);
    texture.path = file.string();
    std::error_code ec;
    if (!fs::exists(fs::status(file, ec))) {
      r.fail(field, "cannot load texture " + file.string() + ": cannot read the file: " +
                        (ec ? ec.message() : std::string("no such file")));
      return;
    }
    const auto image = sim::readPngRgb8(file);
    if (!image) {
      r.fail(field, "cannot load texture " + image.error());
      return;
    }
    texture.width = image->width;
    texture.height = image->height;
    texture.texels.resize(image->pixels.size());
    // 8-bit values taken as linear albedo (no sRGB curve): the scene's textures are synthetic
    // charts whose values are meant as reflectances. Divided, not multiplied by 1/255, so that
    // 255 is exactly 1 and 51 exactly 0.2F.
    std::transform(image->pixels.begin(), image->pixels.end(), texture.texels.begin(),
                   [](const algo::Rgb8& p) {
                     return std::array<float, 3>{static_cast<float>(p.r) / 255.0F,
                                                 static_cast<float>(p.g) / 255.0F,
                                                 static_cast<float>(p.b) / 255.0F};
                   });
  }

  fs::path baseDir_;
  std::map<fs::path, Mesh> meshes_;
};

void readObject(Reader& r, const Json& v, std::size_t index, NameRegistry& names, FileLoader& files,
                Scene& scene) {
  const std::string path = element("objects", index);
  if (!r.object(v, path, "one scene object {\"shape\": ...}", kObjectKeys)) {
    return;
  }
  Object object;
  if (r.find(v, "name") != nullptr) {
    object.name = r.text(v, path, "name", "").value_or(std::string());
    if (r.ok()) {
      names.add(r, object.name, path, true);
    }
  } else {
    object.name = "object" + std::to_string(index);
    names.add(r, object.name, path, false);
  }
  readShape(r, v, path, object.shape);
  if (r.ok()) {
    checkShape(r, object.shape, member(path, "shape"));
  }
  readPose(r, v, path, object.pose);
  if (r.ok()) {
    checkPose(r, object.pose, member(path, "pose"));
  }
  readMotion(r, v, path, object.motion);
  if (r.ok()) {
    checkMotion(r, object.motion, member(path, "motion"));
    object.motion.axis /= object.motion.axis.stableNorm();
  }
  readPoseSequence(r, v, path, object.poseSequence);
  if (r.ok()) {
    checkPoseSequence(r, object.poseSequence, object.motion, member(path, "pose_sequence"));
  }
  readAlbedo(r, v, path, object.albedo);
  if (r.ok()) {
    checkAlbedo(r, object.albedo, member(path, "albedo"));
  }
  r.boolean(v, path, "on_turntable", object.onTurntable);
  files.load(r, path, object);
  checkLoaded(r, object, path);
  scene.objects.push_back(std::move(object));
}

void readObjects(Reader& r, const Json& doc, const fs::path& baseDir, Scene& scene) {
  const auto it = doc.find("objects");
  if (it == doc.end()) {
    r.fail("objects",
           "required field is missing; a scene needs at least one object, e.g. \"objects\": "
           "[{\"shape\": {\"type\": \"plane\"}}]");
    return;
  }
  if (!it->is_array()) {
    r.fail("objects", "must be an array of objects, got " + describe(*it));
    return;
  }
  checkObjectCount(r, it->size());
  NameRegistry names;
  FileLoader files(baseDir);
  for (std::size_t i = 0; i < it->size() && r.ok(); ++i) {
    readObject(r, (*it)[i], i, names, files, scene);
  }
}

std::expected<Scene, SceneError> parseSceneImpl(std::string_view text, const fs::path& baseDir) {
  auto parsed = parseDocument(text, kSceneDocument);
  if (!parsed) {
    auto& e = parsed.error();
    return std::unexpected(SceneError{{}, std::move(e.field), std::move(e.problem)});
  }
  const Json& doc = *parsed;
  Reader r;
  Scene scene;
  r.integer(doc, "", "supersampling", 1, sim::kMaxSceneSupersampling, "samples per pixel side",
            scene.supersampling);
  readLighting(r, doc, scene.lighting);
  checkLighting(r, scene.lighting);
  readCameraResponse(r, doc, scene.camera);
  checkCameraResponse(r, scene.camera);
  readTurntable(r, doc, scene);
  readObjects(r, doc, baseDir, scene);
  checkTurntable(r, scene);
  if (r.ok() && scene.turntable) {
    scene.turntable->axis /= scene.turntable->axis.stableNorm();
  }
  detail::readHandheld(r, doc, scene.handheld);
  if (!r.ok()) {
    return r.error();
  }
  return scene;
}

}  // namespace

std::string SceneError::message() const {
  return errorMessage(file, field, problem);
}

std::expected<Scene, SceneError> parseScene(std::string_view jsonText,
                                            const std::filesystem::path& baseDir) {
  try {
    return parseSceneImpl(jsonText, baseDir);
  } catch (const std::exception& e) {
    // Out of memory or a library surprise: still an error value, never an exception.
    return std::unexpected(SceneError{{}, {}, std::string("cannot read the scene: ") + e.what()});
  }
}

std::expected<void, SceneError> validateScene(const Scene& scene) {
  try {
    Reader r;
    checkSupersampling(r, scene.supersampling);
    checkLighting(r, scene.lighting);
    checkCameraResponse(r, scene.camera);
    checkObjectCount(r, scene.objects.size());
    for (std::size_t i = 0; i < scene.objects.size() && r.ok(); ++i) {
      checkObject(r, scene.objects[i], element("objects", i));
      checkLoaded(r, scene.objects[i], element("objects", i));
    }
    checkTurntable(r, scene);
    if (scene.handheld && r.ok()) {
      detail::checkHandheld(r, *scene.handheld);
    }
    if (!r.ok()) {
      return r.error();
    }
    return {};
  } catch (const std::exception& e) {
    return std::unexpected(SceneError{{}, {}, std::string("cannot check the scene: ") + e.what()});
  }
}

std::expected<Scene, SceneError> loadScene(const std::filesystem::path& file) {
  return loadDocument(file, kSceneDocument, [&](const std::string& text) {
    return parseScene(text, file.parent_path());
  });
}

}  // namespace smx::config
