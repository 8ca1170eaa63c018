#include "smx/sim/renderer.hpp"

#include <embree3/rtcore.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "camera_response.hpp"
#include "gaussian_blur.hpp"
#include "handheld_view.hpp"
#include "shape_geometry.hpp"
#include "smx/algo/lens.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/config/scene_json.hpp"

// The model, its order of operations and the ground-truth definitions are in docs/simulator.md.
namespace smx::sim {
namespace {

namespace lens = algo::lens;
using detail::RgbF;

constexpr unsigned kInvalidId = RTC_INVALID_GEOMETRY_ID;
// Debian's Embree is built with ray masks: a ray with mask 0 hits nothing.
constexpr unsigned kAllGeometry = 0xFFFFFFFFU;
// Shadow rays start this far off the surface along its normal: 100× Embree's float rounding of
// the origin at a few metres, far below any scene detail.
constexpr double kShadowOffsetM = 1e-5;
// Camera sample rays are cached per camera when the table stays below this (640×480 at 3×3
// supersampling fits); otherwise every frame undistorts them again.
constexpr std::size_t kMaxRayTableBytes = std::size_t{64} << 20U;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

struct DeviceDeleter {
  void operator()(RTCDevice d) const { rtcReleaseDevice(d); }
};
struct SceneDeleter {
  void operator()(RTCScene s) const { rtcReleaseScene(s); }
};
struct GeometryDeleter {
  void operator()(RTCGeometry g) const { rtcReleaseGeometry(g); }
};
using DeviceHandle = std::unique_ptr<RTCDeviceTy, DeviceDeleter>;
using SceneHandle = std::unique_ptr<RTCSceneTy, SceneDeleter>;
using GeometryHandle = std::unique_ptr<RTCGeometryTy, GeometryDeleter>;

Vec3 toVec(const lens::Point3& p) {
  return {p[0], p[1], p[2]};
}

// x ∈ [lo, hi); false for NaN.
bool inHalfOpen(double x, double lo, double hi) {
  return x >= lo && x < hi;
}

std::size_t pixelIndex(int x, int y, int width) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
         static_cast<std::size_t>(x);
}

// Object → world at one frame: X = R·(scale·x) + t.
struct FramePose {
  FramePose() = default;
  FramePose(const Mat3& rotation, Vec3 translation, double s)
      : R(rotation), t(std::move(translation)), scale(s), inverse(rotation.transpose() / s) {}

  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  double scale = 1.0;
  Mat3 inverse = Mat3::Identity();  // Rᵀ / scale: the ray callbacks run this per ray

  [[nodiscard]] Vec3 toWorld(const Vec3& x) const { return R * (scale * x) + t; }
  [[nodiscard]] Vec3 toLocal(const Vec3& world) const { return inverse * (world - t); }
  // Keeps the ray parameter: local o + t·d is the local image of world o + t·d.
  [[nodiscard]] Vec3 directionToLocal(const Vec3& d) const { return inverse * d; }
};

// Its pose changes from frame to frame: a motion or a pose sequence.
bool moves(const Object& o) {
  const Motion& m = o.motion;
  return !m.velocityMPerFrame.isZero(0.0) || m.angularDegPerFrame != 0.0 ||
         !o.poseSequence.poses.empty() || o.onTurntable;
}

// The pose a sequence holds at time f (frames): that of the nearest whole frame, so an exposure
// across a switch mixes the two poses as a board being put down does.
FramePose sequencePoseAt(const PoseSequence& sequence, double f) {
  const double frame = std::max(0.0, std::floor(f + 0.5));
  const double held = std::floor(frame / sequence.holdFrames);
  const auto n = static_cast<double>(sequence.poses.size());
  const Pose& p = sequence.poses[static_cast<std::size_t>(held - n * std::floor(held / n))];
  return {p.R, p.t, p.scale};
}

// scene.hpp: rotate by f·angle about `axis` through `pivot`, then translate by f·velocity; f is
// the time in frames (fractional within an exposure).
FramePose poseAt(const Object& object, double f) {
  if (!object.poseSequence.poses.empty()) {
    return sequencePoseAt(object.poseSequence, f);
  }
  if (f == 0.0 || !moves(object)) {
    return {object.pose.R, object.pose.t, object.pose.scale};
  }
  const auto& m = object.motion;
  const Mat3 turn =
      Eigen::AngleAxisd(f * m.angularDegPerFrame * std::numbers::pi / 180.0, m.axis.normalized())
          .toRotationMatrix();
  return {turn * object.pose.R,
          turn * (object.pose.t - m.pivot) + m.pivot + f * m.velocityMPerFrame, object.pose.scale};
}

// The pose `pose` of an object on the scene's turntable once the table has turned by `deg`:
// right-handed about its axis through its pivot (scene.hpp, TurntableMount).
FramePose onTurntable(const Scene& scene, const Object& object, double deg, const FramePose& pose) {
  if (!object.onTurntable || !scene.turntable || deg == 0.0) {
    return pose;
  }
  const TurntableMount& table = *scene.turntable;
  const Mat3 turn =
      Eigen::AngleAxisd(deg * std::numbers::pi / 180.0, table.axis.normalized()).toRotationMatrix();
  return {turn * pose.R, turn * (pose.t - table.pivot) + table.pivot, pose.scale};
}

// Per object: its Embree geometry and, for analytic shapes, the surfaces the user-geometry
// callbacks intersect (geometryUserPtr points here, so the vector holding these never resizes
// after the geometries are created).
struct ObjectState {
  const Object* object = nullptr;
  FramePose pose;  // at the committed time
  std::vector<detail::Surface> surfaces;
  GeometryHandle geometry;  // in the world scene: a user geometry, or an instance of meshScene
  SceneHandle meshScene;    // meshes: the triangles in local coordinates
};

// ---- Embree user-geometry callbacks for the analytic shapes (double inside) ----

float lowerBound(double x, double pad) {
  return std::nextafter(static_cast<float>(x - pad), -INFINITY);
}
float upperBound(double x, double pad) {
  return std::nextafter(static_cast<float>(x + pad), INFINITY);
}

void surfaceBoundsCallback(const RTCBoundsFunctionArguments* args) {
  const auto& state = *static_cast<const ObjectState*>(args->geometryUserPtr);
  const detail::LocalBox local = detail::surfaceBounds(state.surfaces[args->primID]);
  const Vec3 centre = state.pose.toWorld(local.centre);
  const Vec3 half = state.pose.R.cwiseAbs() * (state.pose.scale * local.halfSize);
  const double pad = 1e-6 * (1.0 + centre.cwiseAbs().maxCoeff() + half.maxCoeff());
  RTCBounds& b = *args->bounds_o;
  b.lower_x = lowerBound(centre.x() - half.x(), pad);
  b.lower_y = lowerBound(centre.y() - half.y(), pad);
  b.lower_z = lowerBound(centre.z() - half.z(), pad);
  b.upper_x = upperBound(centre.x() + half.x(), pad);
  b.upper_y = upperBound(centre.y() + half.y(), pad);
  b.upper_z = upperBound(centre.z() + half.z(), pad);
}

struct LocalRay {
  Vec3 origin;
  Vec3 direction;
  double tNear;
  double tFar;
};

LocalRay localRay(const FramePose& pose, RTCRayN* rays, unsigned n, unsigned i) {
  const Vec3 o(RTCRayN_org_x(rays, n, i), RTCRayN_org_y(rays, n, i), RTCRayN_org_z(rays, n, i));
  const Vec3 d(RTCRayN_dir_x(rays, n, i), RTCRayN_dir_y(rays, n, i), RTCRayN_dir_z(rays, n, i));
  return {pose.toLocal(o), pose.directionToLocal(d), RTCRayN_tnear(rays, n, i),
          RTCRayN_tfar(rays, n, i)};
}

void surfaceIntersectCallback(const RTCIntersectFunctionNArguments* args) {
  const auto& state = *static_cast<const ObjectState*>(args->geometryUserPtr);
  const detail::Surface& surface = state.surfaces[args->primID];
  RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) {
      continue;
    }
    const LocalRay r = localRay(state.pose, rays, args->N, i);
    const auto hit = detail::intersectSurface(surface, r.origin, r.direction, r.tNear, r.tFar);
    if (!hit) {
      continue;
    }
    const Vec3 n = state.pose.R * hit->normal;
    RTCRayN_tfar(rays, args->N, i) = static_cast<float>(hit->t);
    RTCHitN_Ng_x(hits, args->N, i) = static_cast<float>(n.x());
    RTCHitN_Ng_y(hits, args->N, i) = static_cast<float>(n.y());
    RTCHitN_Ng_z(hits, args->N, i) = static_cast<float>(n.z());
    RTCHitN_u(hits, args->N, i) = 0.0F;
    RTCHitN_v(hits, args->N, i) = 0.0F;
    RTCHitN_primID(hits, args->N, i) = args->primID;
    RTCHitN_geomID(hits, args->N, i) = args->geomID;
    RTCHitN_instID(hits, args->N, i, 0) = args->context->instID[0];
  }
}

void surfaceOccludedCallback(const RTCOccludedFunctionNArguments* args) {
  const auto& state = *static_cast<const ObjectState*>(args->geometryUserPtr);
  const detail::Surface& surface = state.surfaces[args->primID];
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) {
      continue;
    }
    const LocalRay r = localRay(state.pose, args->ray, args->N, i);
    if (detail::intersectSurface(surface, r.origin, r.direction, r.tNear, r.tFar)) {
      RTCRayN_tfar(args->ray, args->N, i) = -INFINITY;  // Embree's "occluded"
    }
  }
}

void setInstanceTransform(RTCGeometry instance, const FramePose& pose) {
  std::array<float, 12> m{};  // 3×4 column-major [R·scale | t]
  for (std::size_t col = 0; col < 3; ++col) {
    const auto c = static_cast<Eigen::Index>(col);
    for (std::size_t row = 0; row < 3; ++row) {
      m[col * 3 + row] = static_cast<float>(pose.scale * pose.R(static_cast<Eigen::Index>(row), c));
    }
    m[9 + col] = static_cast<float>(pose.t[c]);
  }
  rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m.data());
}

Vec3 albedoAt(const Albedo& albedo, const Vec3& local) {
  if (const auto* c = std::get_if<CheckerTexture>(&albedo.texture)) {
    const auto n = static_cast<double>(c->colours.size());
    double k =
        std::fmod(std::floor(local.x() / c->squareM) + std::floor(local.y() / c->squareM), n);
    if (k < 0.0) {
      k += n;
    }
    return c->colours[std::min(static_cast<std::size_t>(k), c->colours.size() - 1)];
  }
  if (const auto* t = std::get_if<ImageTexture>(&albedo.texture)) {
    // Nearest texel; row 0 at local y = −h/2 (y points down, like image rows); repeats.
    double fu = local.x() / t->widthM + 0.5;
    double fv = local.y() / t->heightM + 0.5;
    fu -= std::floor(fu);
    fv -= std::floor(fv);
    const int col = std::min(static_cast<int>(fu * t->width), t->width - 1);
    const int row = std::min(static_cast<int>(fv * t->height), t->height - 1);
    const auto& texel = t->texels[pixelIndex(col, row, t->width)];
    return {texel[0], texel[1], texel[2]};
  }
  return albedo.rgb;
}

// Runs fn(y) for every row, rows shared dynamically between the hardware threads. Each row must
// write only its own outputs; then the result does not depend on the split.
template <class Fn>
void forEachRow(int height, const Fn& fn) {
  std::atomic<int> nextRow{0};
  const auto work = [&] {
    for (int y = nextRow++; y < height; y = nextRow++) {
      fn(y);
    }
  };
  const unsigned threads = std::clamp(std::thread::hardware_concurrency(), 1U, 16U);
  std::vector<std::jthread> helpers;
  for (unsigned i = 1; i < threads && static_cast<int>(i) < height; ++i) {
    helpers.emplace_back(work);
  }
  work();
}

struct SurfacePoint {
  Vec3 point;
  Vec3 normal;  // unit, world, facing the ray's origin
  std::size_t object = 0;
};

// A surface point as one projector lights it.
struct Illumination {
  double u = 0.0;  // continuous projector pixel coordinates
  double v = 0.0;
  std::size_t pixel = 0;  // the projector pixel containing (u, v), row-major
  double cosTheta = 0.0;
  double distanceM = 0.0;
};

// Blinn–Phong lobe (n·h)^shininess, h the half vector of the unit directions to the light and to
// the eye; 0 where h points away from the surface.
double blinnPhong(const Vec3& normal, const Vec3& toLight, const Vec3& toEye, double shininess) {
  const double cosine = normal.dot((toLight + toEye).normalized());
  return cosine > 0.0 ? std::pow(cosine, shininess) : 0.0;
}

struct ProjectorState {
  Vec3 centre;
  std::vector<RgbF> light;  // emitted light per pattern pixel after the defocus blur, row-major
};

class EmbreeRenderer final : public Renderer {
 public:
  EmbreeRenderer(algo::Rig rig, Scene scene) : rig_(std::move(rig)), scene_(std::move(scene)) {}

  std::expected<void, std::string> init();

  std::expected<void, std::string> render(const FrameRequest& request, algo::RgbView image,
                                          GroundTruthViews* truth) override;

 private:
  struct FrameContext {
    const algo::Camera* camera = nullptr;
    std::vector<double> projectorWeight;  // per projector: 0 dark, else its power
    GroundTruthViews* truth = nullptr;
    std::vector<double> sampleOffsets;              // stratum centres within a pixel, per axis
    const std::vector<RgbF>* sampleRays = nullptr;  // cached directions, or null: undistort
    double timeWeight = 1.0;                        // of this time sample in the exposure
    bool firstTime = true;                          // the first time sample: overwrite
  };

  std::expected<void, std::string> initProjectors();
  std::expected<void, std::string> initGeometry();
  std::expected<void, std::string> check(const FrameRequest& request, algo::RgbView image,
                                         const GroundTruthViews* truth) const;
  void setTime(double time);
  [[nodiscard]] FramePose framePose(const Object& object, double time) const;
  [[nodiscard]] std::vector<double> exposureTimes(int frame) const;
  const std::vector<RgbF>* sampleRays(const FrameContext& ctx, int cameraIndex);
  void shadeRow(const FrameContext& ctx, int y);
  void exposeRow(const algo::Camera& camera, double signalScale, int y);
  void writeTruth(const FrameContext& ctx, int x, int y) const;
  void addNoiseAndQuantise(const FrameRequest& request, algo::RgbView image) const;

  [[nodiscard]] std::optional<SurfacePoint> trace(const Vec3& origin, const Vec3& dir) const;
  [[nodiscard]] bool occluded(const Vec3& from, const Vec3& to) const;
  [[nodiscard]] std::optional<Illumination> illuminate(std::size_t p, const SurfacePoint& s) const;
  [[nodiscard]] Vec3 radiance(const SurfacePoint& s, const std::vector<double>& projectorWeight,
                              const Vec3& eye) const;

  algo::Rig rig_;
  Scene scene_;
  std::vector<ProjectorState> projectors_;
  std::string embreeError_;  // outlives device_: the error callback writes here
  DeviceHandle device_;
  std::vector<ObjectState> objects_;  // index = geometry ID in world_
  SceneHandle world_;
  bool anyMotion_ = false;
  std::optional<detail::HandheldView> handheld_;  // the rig moves: the world is drawn around it
  double time_ = 0.0;                             // the time (frames) world_ is committed for
  double turntableDeg_ = 0.0;                     // and the turntable angle
  std::optional<detail::BayerCell> bayer_;
  std::vector<Vec3> radiance_;  // per pixel: mean reflected light over samples and exposure
  std::vector<RgbF> linear_;
  std::vector<std::vector<RgbF>> sampleRays_;  // per camera: direction of every sample, float
};

std::expected<void, std::string> EmbreeRenderer::init() {
  // scene.json's own rules, and no others: the renderer draws every scene a file may describe.
  if (auto valid = config::validateScene(scene_); !valid) {
    return std::unexpected(valid.error().message());
  }
  if (auto ok = initProjectors(); !ok) {
    return ok;
  }
  bayer_ = detail::bayerCell(scene_.camera.bayer);
  if (scene_.handheld) {
    handheld_.emplace(*scene_.handheld, scene_.objects);
  }
  return initGeometry();
}

// The projector's display: a pattern level in [0, 1] becomes black + (1 − black)·level^γ of a full
// pixel's light. Before the lens blur, which acts on the emitted light.
void emit(std::vector<RgbF>& light, double black, double gamma) {
  if (black == 0.0 && gamma == 1.0) {
    return;
  }
  for (RgbF& px : light) {
    for (float& c : px) {
      c = static_cast<float>(black + (1.0 - black) * std::pow(static_cast<double>(c), gamma));
    }
  }
}

std::expected<void, std::string> EmbreeRenderer::initProjectors() {
  projectors_.resize(rig_.projectors.size());
  for (std::size_t p = 0; p < rig_.projectors.size(); ++p) {
    const auto& model = rig_.projectors[p];
    const std::string name = "projectors[" + std::to_string(p) + "]: ";
    if (model.width <= 0 || model.height <= 0) {
      return std::unexpected(name + "image size must be positive");
    }
    const std::size_t count =
        static_cast<std::size_t>(model.width) * static_cast<std::size_t>(model.height);
    std::vector<algo::Rgb8> pattern(count);
    auto view = algo::RgbView::packed(pattern, model.width, model.height);
    if (!view) {
      return std::unexpected(name + view.error().message);
    }
    if (auto ok = algo::renderPatternImage(model, *view); !ok) {
      return std::unexpected(name + ok.error().message);
    }
    auto& state = projectors_[p];
    state.centre = toVec(lens::centre(model));
    state.light.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      state.light[i] = {static_cast<float>(pattern[i].r) / 255.0F,
                        static_cast<float>(pattern[i].g) / 255.0F,
                        static_cast<float>(pattern[i].b) / 255.0F};
    }
    emit(state.light, scene_.lighting.projectorBlackLevel, scene_.lighting.projectorGamma);
    detail::gaussianBlur(state.light, model.width, model.height,
                         scene_.lighting.projectorDefocusSigmaPx, detail::Border::kBlack);
  }
  return {};
}

std::expected<void, std::string> EmbreeRenderer::initGeometry() {
  device_.reset(rtcNewDevice(nullptr));
  if (!device_) {
    return std::unexpected("Embree: cannot create a device (error " +
                           std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
  }
  rtcSetDeviceErrorFunction(
      device_.get(),
      [](void* user, RTCError code, const char* text) {
        auto& error = *static_cast<std::string*>(user);
        if (error.empty()) {
          error = "Embree error " + std::to_string(static_cast<int>(code)) + ": " +
                  (text != nullptr ? text : "");
        }
      },
      &embreeError_);

  anyMotion_ = handheld_.has_value();
  for (const auto& o : scene_.objects) {
    anyMotion_ = anyMotion_ || moves(o);
  }
  world_.reset(rtcNewScene(device_.get()));
  rtcSetSceneFlags(world_.get(), anyMotion_ ? (RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_DYNAMIC)
                                            : RTC_SCENE_FLAG_ROBUST);

  objects_.resize(scene_.objects.size());  // never resized again: callbacks point into it
  for (std::size_t i = 0; i < objects_.size(); ++i) {
    auto& state = objects_[i];
    state.object = &scene_.objects[i];
    state.pose = framePose(*state.object, 0);
    if (const auto* mesh = std::get_if<Mesh>(&state.object->shape)) {
      // Triangles in local coordinates, built once; per frame only the instance moves.
      state.meshScene.reset(rtcNewScene(device_.get()));
      rtcSetSceneFlags(state.meshScene.get(), RTC_SCENE_FLAG_ROBUST);
      rtcSetSceneBuildQuality(state.meshScene.get(), RTC_BUILD_QUALITY_HIGH);
      const GeometryHandle triangles(rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_TRIANGLE));
      auto* vertices = static_cast<float*>(
          rtcSetNewGeometryBuffer(triangles.get(), RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                  3 * sizeof(float), mesh->vertices.size()));
      auto* indices = static_cast<std::uint32_t*>(
          rtcSetNewGeometryBuffer(triangles.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                  3 * sizeof(std::uint32_t), mesh->triangles.size()));
      if (vertices == nullptr || indices == nullptr) {
        return std::unexpected("objects[" + std::to_string(i) + "]: Embree: " + embreeError_);
      }
      for (std::size_t v = 0; v < mesh->vertices.size(); ++v) {
        for (std::size_t c = 0; c < 3; ++c) {
          vertices[3 * v + c] = mesh->vertices[v][static_cast<Eigen::Index>(c)];
        }
      }
      for (std::size_t t = 0; t < mesh->triangles.size(); ++t) {
        for (std::size_t c = 0; c < 3; ++c) {
          indices[3 * t + c] = mesh->triangles[t][c];
        }
      }
      rtcCommitGeometry(triangles.get());
      rtcAttachGeometry(state.meshScene.get(), triangles.get());
      rtcCommitScene(state.meshScene.get());
      state.geometry.reset(rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_INSTANCE));
      rtcSetGeometryInstancedScene(state.geometry.get(), state.meshScene.get());
      setInstanceTransform(state.geometry.get(), state.pose);
    } else {
      const int count = detail::surfaceCount(state.object->shape);
      for (int s = 0; s < count; ++s) {
        state.surfaces.push_back(detail::surfaceOf(state.object->shape, s));
      }
      state.geometry.reset(rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_USER));
      rtcSetGeometryUserPrimitiveCount(state.geometry.get(), static_cast<unsigned>(count));
      rtcSetGeometryUserData(state.geometry.get(), &state);
      rtcSetGeometryBoundsFunction(state.geometry.get(), surfaceBoundsCallback, nullptr);
      rtcSetGeometryIntersectFunction(state.geometry.get(), surfaceIntersectCallback);
      rtcSetGeometryOccludedFunction(state.geometry.get(), surfaceOccludedCallback);
    }
    rtcSetGeometryMask(state.geometry.get(), kAllGeometry);
    rtcCommitGeometry(state.geometry.get());
    rtcAttachGeometryByID(world_.get(), state.geometry.get(), static_cast<unsigned>(i));
  }
  rtcCommitScene(world_.get());
  if (!embreeError_.empty()) {
    return std::unexpected(embreeError_);
  }
  return {};
}

void EmbreeRenderer::setTime(double time) {
  if (time == time_ || !anyMotion_) {
    return;
  }
  for (auto& state : objects_) {
    if (!handheld_ && !moves(*state.object)) {
      continue;
    }
    state.pose = framePose(*state.object, time);
    if (state.meshScene) {
      setInstanceTransform(state.geometry.get(), state.pose);
    }
    rtcCommitGeometry(state.geometry.get());  // user geometries: bounds read the new pose
  }
  rtcCommitScene(world_.get());
  time_ = time;
}

// The object's pose at `time` in the rig's frame (the world's when the rig stands still), on the
// turntable at its angle.
FramePose EmbreeRenderer::framePose(const Object& object, double time) const {
  FramePose world = onTurntable(scene_, object, turntableDeg_, poseAt(object, time));
  if (!handheld_) {
    return world;
  }
  const Pose p = handheld_->seenFromRig(object, {world.R, world.t, world.scale}, time);
  return {p.R, p.t, p.scale};
}

// The frame's instant, or the stratum centres of [frame − e/2, frame + e/2] when something
// moves during a non-zero exposure e (a still scene looks the same at every instant).
std::vector<double> EmbreeRenderer::exposureTimes(int frame) const {
  const double e = scene_.camera.exposure;
  const int n = scene_.camera.exposureSamples;
  if (!(e > 0.0) || !anyMotion_ || n <= 1) {
    return {static_cast<double>(frame)};
  }
  std::vector<double> times;
  times.reserve(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    times.push_back(frame + e * ((k + 0.5) / n - 0.5));
  }
  return times;
}

std::optional<SurfacePoint> EmbreeRenderer::trace(const Vec3& origin, const Vec3& dir) const {
  RTCIntersectContext context{};
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = static_cast<float>(origin.x());
  rh.ray.org_y = static_cast<float>(origin.y());
  rh.ray.org_z = static_cast<float>(origin.z());
  rh.ray.dir_x = static_cast<float>(dir.x());
  rh.ray.dir_y = static_cast<float>(dir.y());
  rh.ray.dir_z = static_cast<float>(dir.z());
  rh.ray.tnear = 0.0F;
  rh.ray.tfar = INFINITY;
  rh.ray.time = 0.0F;
  rh.ray.mask = kAllGeometry;
  rh.ray.flags = 0;
  rh.hit.geomID = kInvalidId;
  rh.hit.instID[0] = kInvalidId;
  rtcIntersect1(world_.get(), &context, &rh);
  if (rh.hit.geomID == kInvalidId) {
    return std::nullopt;
  }
  // Embree found which surface the float ray hits first; the point and normal are recomputed
  // from the double ray on that surface (docs/simulator.md, "Precision").
  SurfacePoint s;
  s.object = rh.hit.instID[0] != kInvalidId ? rh.hit.instID[0] : rh.hit.geomID;
  const ObjectState& state = objects_[s.object];
  const double tEmbree = rh.ray.tfar;
  if (const auto* mesh = std::get_if<Mesh>(&state.object->shape)) {
    const auto& tri = mesh->triangles[rh.hit.primID];
    const Vec3 a = state.pose.toWorld(mesh->vertices[tri[0]].cast<double>());
    const Vec3 b = state.pose.toWorld(mesh->vertices[tri[1]].cast<double>());
    const Vec3 c = state.pose.toWorld(mesh->vertices[tri[2]].cast<double>());
    const Vec3 n = (b - a).cross(c - a);
    const double denominator = n.dot(dir);
    const double t = denominator != 0.0 ? n.dot(a - origin) / denominator : tEmbree;
    s.point = origin + (std::isfinite(t) ? t : tEmbree) * dir;
    s.normal = n.squaredNorm() > 0.0
                   ? n.normalized()
                   : (state.pose.R * Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z)).normalized();
  } else {
    const detail::LocalHit hit =
        detail::refineSurface(state.surfaces[rh.hit.primID], state.pose.toLocal(origin),
                              state.pose.directionToLocal(dir), tEmbree);
    s.point = origin + hit.t * dir;
    s.normal = (state.pose.R * hit.normal).normalized();
  }
  if (s.normal.dot(dir) > 0.0) {
    s.normal = -s.normal;  // two-sided: the side the ray comes from
  }
  return s;
}

bool EmbreeRenderer::occluded(const Vec3& from, const Vec3& to) const {
  const Vec3 d = to - from;
  const double length = d.norm();
  const Vec3 dir = d / length;
  RTCIntersectContext context{};
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = static_cast<float>(from.x());
  ray.org_y = static_cast<float>(from.y());
  ray.org_z = static_cast<float>(from.z());
  ray.dir_x = static_cast<float>(dir.x());
  ray.dir_y = static_cast<float>(dir.y());
  ray.dir_z = static_cast<float>(dir.z());
  ray.tnear = 0.0F;
  ray.tfar = static_cast<float>(length);
  ray.time = 0.0F;
  ray.mask = kAllGeometry;
  ray.flags = 0;
  rtcOccluded1(world_.get(), &context, &ray);
  return ray.tfar < 0.0F;  // Embree sets tfar = −inf when something is in the way
}

std::optional<Illumination> EmbreeRenderer::illuminate(std::size_t p, const SurfacePoint& s) const {
  const auto& model = rig_.projectors[p];
  const ProjectorState& projector = projectors_[p];
  const Vec3 toProjector = projector.centre - s.point;
  Illumination il;
  il.distanceM = toProjector.norm();
  il.cosTheta = s.normal.dot(toProjector) / il.distanceM;
  if (!(il.cosTheta > 0.0)) {
    return std::nullopt;  // the projector is behind the surface the camera sees
  }
  const auto uv = lens::project(model, {s.point.x(), s.point.y(), s.point.z()});
  // Square pixels: the pixel whose centre is nearest, inside [−½, W−½) × [−½, H−½).
  if (!uv || !inHalfOpen(uv->x, -0.5, model.width - 0.5) ||
      !inHalfOpen(uv->y, -0.5, model.height - 0.5)) {
    return std::nullopt;
  }
  il.u = uv->x;
  il.v = uv->y;
  const int col = std::min(static_cast<int>(std::floor(il.u + 0.5)), model.width - 1);
  const int row = std::min(static_cast<int>(std::floor(il.v + 0.5)), model.height - 1);
  il.pixel = pixelIndex(col, row, model.width);
  if (occluded(s.point + kShadowOffsetM * s.normal, projector.centre)) {
    return std::nullopt;
  }
  return il;
}

Vec3 EmbreeRenderer::radiance(const SurfacePoint& s, const std::vector<double>& projectorWeight,
                              const Vec3& eye) const {
  const auto& lighting = scene_.lighting;
  const ObjectState& state = objects_[s.object];
  const Albedo& albedo = state.object->albedo;
  Vec3 irradiance = lighting.ambient;
  Vec3 gloss = Vec3::Zero();
  for (std::size_t p = 0; p < projectors_.size(); ++p) {
    if (projectorWeight[p] <= 0.0) {
      continue;
    }
    const auto il = illuminate(p, s);
    if (!il) {
      continue;
    }
    double w = lighting.projectorPower * projectorWeight[p] * il->cosTheta;
    if (lighting.inverseSquare) {
      const double ratio = lighting.referenceDistanceM / il->distanceM;
      w *= ratio * ratio;
    }
    const RgbF& c = projectors_[p].light[il->pixel];
    const Vec3 e = w * Vec3(c[0], c[1], c[2]);
    irradiance += e;
    if (albedo.specular > 0.0) {
      const Vec3 toLight = (projectors_[p].centre - s.point) / il->distanceM;
      gloss += albedo.specular *
               blinnPhong(s.normal, toLight, (eye - s.point).normalized(), albedo.shininess) * e;
    }
  }
  const Vec3 diffuse = std::holds_alternative<std::monostate>(albedo.texture)
                           ? albedo.rgb.cwiseProduct(irradiance)
                           : albedoAt(albedo, state.pose.toLocal(s.point)).cwiseProduct(irradiance);
  return albedo.specular > 0.0 ? Vec3(diffuse + gloss) : diffuse;
}

void EmbreeRenderer::shadeRow(const FrameContext& ctx, int y) {
  const algo::Camera& camera = *ctx.camera;
  const Vec3 centre = toVec(lens::centre(camera));
  const double perSample =
      1.0 / static_cast<double>(ctx.sampleOffsets.size() * ctx.sampleOffsets.size());
  for (int x = 0; x < camera.width; ++x) {
    Vec3 sum = Vec3::Zero();
    std::size_t sample =
        pixelIndex(x, y, camera.width) * ctx.sampleOffsets.size() * ctx.sampleOffsets.size();
    for (const double dy : ctx.sampleOffsets) {
      for (const double dx : ctx.sampleOffsets) {
        Vec3 dir = Vec3::Constant(NAN);
        if (ctx.sampleRays != nullptr) {
          const RgbF& d = (*ctx.sampleRays)[sample++];
          dir = {d[0], d[1], d[2]};
        } else if (const auto ray = lens::pixelRay(camera, {x + dx, y + dy})) {
          dir = toVec(ray->direction);
        }
        if (!dir.allFinite()) {
          continue;  // beyond the range of the distortion model
        }
        if (const auto s = trace(centre, dir)) {
          sum += radiance(*s, ctx.projectorWeight, centre);
        }
      }
    }
    const Vec3 mean = ctx.timeWeight * (perSample * sum);
    Vec3& out = radiance_[pixelIndex(x, y, camera.width)];
    out = ctx.firstTime ? mean : Vec3(out + mean);
  }
}

// Vignetting, then crosstalk and gain: linear grey levels.
void EmbreeRenderer::exposeRow(const algo::Camera& camera, double signalScale, int y) {
  const detail::Vignetting vignetting(camera, scene_.camera.vignetting);
  const Mat3 response = signalScale * scene_.camera.gain * 255.0 * scene_.camera.crosstalk;
  for (int x = 0; x < camera.width; ++x) {
    const std::size_t i = pixelIndex(x, y, camera.width);
    const Vec3 grey = response * (vignetting.gain(x, y) * radiance_[i]);
    linear_[i] = {static_cast<float>(grey.x()), static_cast<float>(grey.y()),
                  static_cast<float>(grey.z())};
  }
}

void EmbreeRenderer::writeTruth(const FrameContext& ctx, int x, int y) const {
  const algo::Camera& camera = *ctx.camera;
  GroundTruthViews& truth = *ctx.truth;
  const auto ray = lens::pixelRay(camera, {static_cast<double>(x), static_cast<double>(y)});
  const auto s = ray ? trace(toVec(ray->origin), toVec(ray->direction)) : std::nullopt;
  if (!truth.depth.empty()) {
    truth.depth(x, y) = s ? static_cast<float>(lens::toDevice(
                                camera, {s->point.x(), s->point.y(), s->point.z()})[2])
                          : kNaN;
  }
  if (!truth.normal.empty()) {
    truth.normal(x, y) = s ? std::array<float, 3>{static_cast<float>(s->normal.x()),
                                                  static_cast<float>(s->normal.y()),
                                                  static_cast<float>(s->normal.z())}
                           : std::array<float, 3>{kNaN, kNaN, kNaN};
  }
  for (std::size_t p = 0; p < truth.projectors.size(); ++p) {
    std::uint8_t mask = 0;
    double u = NAN;
    double v = NAN;
    double stripe = NAN;
    if (const auto il = s ? illuminate(p, *s) : std::nullopt) {
      const auto& model = rig_.projectors[p];
      mask = 255;
      u = il->u;
      v = il->v;
      stripe = algo::stripeCoordinate(model.pattern, model.width, model.height, u, v);
    }
    const ProjectorTruthViews& views = truth.projectors[p];
    if (!views.litMask.empty()) {
      views.litMask(x, y) = mask;
    }
    if (!views.u.empty()) {
      views.u(x, y) = static_cast<float>(u);
    }
    if (!views.v.empty()) {
      views.v(x, y) = static_cast<float>(v);
    }
    if (!views.stripe.empty()) {
      views.stripe(x, y) = static_cast<float>(stripe);
    }
  }
}

void EmbreeRenderer::addNoiseAndQuantise(const FrameRequest& request, algo::RgbView image) const {
  const Vec3 sigma = request.gain * scene_.camera.noiseSigma;
  const bool noisy = (sigma.array() > 0.0).any();
  // One stream per (seed, frame, camera), drawn in raster order after shading: the image does
  // not depend on how rows were shared between threads.
  std::seed_seq seeds{static_cast<std::uint32_t>(request.seed & 0xFFFFFFFFU),
                      static_cast<std::uint32_t>(request.seed >> 32U),
                      static_cast<std::uint32_t>(request.frame),
                      static_cast<std::uint32_t>(request.camera)};
  std::mt19937_64 rng(seeds);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const RgbF& in = linear_[pixelIndex(x, y, image.width())];
      std::array<std::uint8_t, 3> out{};
      for (std::size_t c = 0; c < 3; ++c) {
        double level = in[c];
        if (noisy) {
          level += sigma[static_cast<Eigen::Index>(c)] * gauss(rng);
        }
        level = level > 0.0 ? std::min(level, 255.0) : 0.0;
        out[c] = static_cast<std::uint8_t>(std::floor(level + 0.5));
      }
      image(x, y) = algo::Rgb8{out[0], out[1], out[2]};
    }
  }
}

std::expected<void, std::string> EmbreeRenderer::check(const FrameRequest& request,
                                                       algo::RgbView image,
                                                       const GroundTruthViews* truth) const {
  if (request.camera < 0 || static_cast<std::size_t>(request.camera) >= rig_.cameras.size()) {
    return std::unexpected("camera index " + std::to_string(request.camera) +
                           " is out of range; the rig has " + std::to_string(rig_.cameras.size()) +
                           " camera(s)");
  }
  const auto& camera = rig_.cameras[static_cast<std::size_t>(request.camera)];
  const std::string size = std::to_string(camera.width) + "x" + std::to_string(camera.height);
  const auto wrongSize = [&](const auto& view) {
    return view.width() != camera.width || view.height() != camera.height;
  };
  const auto wrongTruth = [&](const auto& view) { return !view.empty() && wrongSize(view); };
  if (wrongSize(image)) {
    return std::unexpected("image is " + std::to_string(image.width()) + "x" +
                           std::to_string(image.height()) + ", camera " + camera.id + " is " +
                           size);
  }
  if (request.lit.size() != rig_.projectors.size()) {
    return std::unexpected("lit has " + std::to_string(request.lit.size()) +
                           " entries; the rig has " + std::to_string(rig_.projectors.size()) +
                           " projector(s)");
  }
  if (!request.power.empty() && request.power.size() != request.lit.size()) {
    return std::unexpected("power has " + std::to_string(request.power.size()) +
                           " entries; the rig has " + std::to_string(rig_.projectors.size()) +
                           " projector(s)");
  }
  const auto unit = [](double v) { return v >= 0.0 && v <= 1.0; };
  if (!std::ranges::all_of(request.power, unit) || !(request.exposureScale > 0.0) ||
      !(request.gain > 0.0) || !std::isfinite(request.exposureScale * request.gain) ||
      !std::isfinite(request.turntableDeg)) {
    return std::unexpected(
        "projector power must be in [0, 1], exposure scale and gain positive, the turntable angle "
        "finite");
  }
  if (truth == nullptr) {
    return {};
  }
  if (wrongTruth(truth->depth) || wrongTruth(truth->normal)) {
    return std::unexpected("ground-truth depth/normal view is not the camera's size " + size);
  }
  if (!truth->projectors.empty() && truth->projectors.size() != rig_.projectors.size()) {
    return std::unexpected("ground truth has " + std::to_string(truth->projectors.size()) +
                           " projector entries; the rig has " +
                           std::to_string(rig_.projectors.size()));
  }
  for (std::size_t p = 0; p < truth->projectors.size(); ++p) {
    const auto& v = truth->projectors[p];
    if (wrongTruth(v.litMask) || wrongTruth(v.u) || wrongTruth(v.v) || wrongTruth(v.stripe)) {
      return std::unexpected("ground truth of projectors[" + std::to_string(p) +
                             "]: a view is not the camera's size " + size);
    }
  }
  return {};
}

const std::vector<RgbF>* EmbreeRenderer::sampleRays(const FrameContext& ctx, int cameraIndex) {
  const algo::Camera& camera = *ctx.camera;
  const std::size_t perPixel = ctx.sampleOffsets.size() * ctx.sampleOffsets.size();
  const std::size_t count = pixelIndex(0, camera.height, camera.width) * perPixel;
  if (count * sizeof(RgbF) > kMaxRayTableBytes) {
    return nullptr;
  }
  sampleRays_.resize(rig_.cameras.size());
  auto& table = sampleRays_[static_cast<std::size_t>(cameraIndex)];
  if (table.size() == count) {
    return &table;
  }
  // Undistorting is a Newton iteration per ray; a static camera's rays are the same every frame.
  // Float directions are ~1e-7 rad off, far below a sample's footprint; the ground truth uses
  // the exact double ray of each pixel centre instead.
  table.assign(count, RgbF{NAN, NAN, NAN});
  forEachRow(camera.height, [&](int y) {
    std::size_t sample = pixelIndex(0, y, camera.width) * perPixel;
    for (int x = 0; x < camera.width; ++x) {
      for (const double dy : ctx.sampleOffsets) {
        for (const double dx : ctx.sampleOffsets) {
          if (const auto ray = lens::pixelRay(camera, {x + dx, y + dy})) {
            table[sample] = {static_cast<float>(ray->direction[0]),
                             static_cast<float>(ray->direction[1]),
                             static_cast<float>(ray->direction[2])};
          }
          ++sample;
        }
      }
    }
  });
  return &table;
}

std::expected<void, std::string> EmbreeRenderer::render(const FrameRequest& request,
                                                        algo::RgbView image,
                                                        GroundTruthViews* truth) {
  if (auto ok = check(request, image, truth); !ok) {
    return ok;
  }
  FrameContext ctx;
  ctx.camera = &rig_.cameras[static_cast<std::size_t>(request.camera)];
  for (std::size_t p = 0; p < request.lit.size(); ++p) {
    ctx.projectorWeight.push_back(!request.lit[p]         ? 0.0
                                  : request.power.empty() ? 1.0
                                                          : request.power[p]);
  }
  ctx.truth = truth;
  const int n = scene_.supersampling;
  for (int i = 0; i < n; ++i) {
    ctx.sampleOffsets.push_back((i + 0.5) / n - 0.5);
  }
  ctx.sampleRays = sampleRays(ctx, request.camera);
  const int width = ctx.camera->width;
  const int height = ctx.camera->height;
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  radiance_.resize(pixels);
  linear_.resize(pixels);
  if (request.turntableDeg != turntableDeg_) {
    turntableDeg_ = request.turntableDeg;
    time_ = NAN;  // every pose is committed again at the new angle
  }
  const std::vector<double> times = exposureTimes(request.frame);
  ctx.timeWeight = 1.0 / static_cast<double>(times.size());
  for (std::size_t k = 0; k < times.size(); ++k) {
    setTime(times[k]);
    ctx.firstTime = k == 0;
    forEachRow(height, [&](int y) { shadeRow(ctx, y); });
  }
  forEachRow(height,
             [&](int y) { exposeRow(*ctx.camera, request.exposureScale * request.gain, y); });
  detail::gaussianBlur(linear_, width, height, scene_.camera.defocusSigmaPx,
                       detail::Border::kClampToEdge);
  detail::applyResponseGamma(linear_, scene_.camera.responseGamma);
  addNoiseAndQuantise(request, image);
  if (bayer_) {
    detail::mosaicAndDemosaic(image, *bayer_);
  }
  if (truth != nullptr) {
    // At the frame's own instant, the middle of the exposure.
    setTime(request.frame);
    forEachRow(height, [&](int y) {
      for (int x = 0; x < width; ++x) {
        writeTruth(ctx, x, y);
      }
    });
  }
  return {};
}

}  // namespace

std::expected<std::unique_ptr<Renderer>, std::string> Renderer::create(const algo::Rig& rig,
                                                                       const Scene& scene) {
  auto renderer = std::make_unique<EmbreeRenderer>(rig, scene);
  if (auto ok = renderer->init(); !ok) {
    return std::unexpected(ok.error());
  }
  return std::unique_ptr<Renderer>(std::move(renderer));
}

}  // namespace smx::sim
