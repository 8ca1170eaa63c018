#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "closed_form_optics.hpp"
#include "smx/algo/lens.hpp"
#include "smx/algo/stripe_code.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/sim/renderer.hpp"
#include "source_dir.hpp"

// The renderer against geometry computed here, independently: ray–shape intersections, the
// projection of docs/rig-format.md and the stripe formula of docs/pattern.md. Cameras are shrunk
// (same field of view, fewer pixels) or cropped (same rays, fewer pixels) to keep the suite fast
// under sanitizers.
namespace smx::sim {
namespace {

using algo::Rgb8;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

algo::Rig exampleRig(const std::string& name) {
  auto rig = config::loadRig(smx::test::sourceDir() / "boards" / "sim" / name);
  if (!rig) {
    ADD_FAILURE() << rig.error().message();
    return {};
  }
  return *rig;
}

// The same field of view at 1/factor the resolution (pixel centres stay at integers).
void shrink(algo::DeviceModel& c, int factor) {
  const double f = factor;
  c.K[0] /= f;
  c.K[4] /= f;
  c.K[2] = (c.K[2] - (f - 1.0) / 2.0) / f;
  c.K[5] = (c.K[5] - (f - 1.0) / 2.0) / f;
  c.width /= factor;
  c.height /= factor;
}

// The window [x0, x0 + w) × [y0, y0 + h) of the camera: the same rays at those pixels.
void crop(algo::DeviceModel& c, int x0, int y0, int w, int h) {
  c.K[2] -= x0;
  c.K[5] -= y0;
  c.width = w;
  c.height = h;
}

Mat3 rotation(double degX, double degY, double degZ) {
  const double k = std::numbers::pi / 180.0;
  return (Eigen::AngleAxisd(degZ * k, Vec3::UnitZ()) * Eigen::AngleAxisd(degY * k, Vec3::UnitY()) *
          Eigen::AngleAxisd(degX * k, Vec3::UnitX()))
      .toRotationMatrix();
}

Object makeObject(Shape shape, const Mat3& R, const Vec3& t, double scale = 1.0) {
  Object o;
  o.shape = std::move(shape);
  o.pose.R = R;
  o.pose.t = t;
  o.pose.scale = scale;
  return o;
}

Object wall(double z) {
  return makeObject(Plane{3.0, 3.0}, Mat3::Identity(), {0.0, 0.0, z});
}

// Noise-free, ambient-free, one sample per pixel: what the geometry tests want.
Scene quietScene() {
  Scene s;
  s.lighting.ambient = Vec3::Zero();
  s.camera.noiseSigma = Vec3::Zero();
  s.supersampling = 1;
  return s;
}

std::size_t at(int x, int y, int width) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
         static_cast<std::size_t>(x);
}

// An image and all ground-truth buffers for one camera.
struct Frame {
  Frame(const algo::DeviceModel& camera, std::size_t projectors)
      : width(camera.width),
        height(camera.height),
        image(count()),
        depth(count()),
        normal(count()) {
    truth.depth = *algo::ImageView<float>::packed(depth, width, height);
    truth.normal = *algo::ImageView<std::array<float, 3>>::packed(normal, width, height);
    mask.resize(projectors, std::vector<std::uint8_t>(count()));
    u.resize(projectors, std::vector<float>(count()));
    v.resize(projectors, std::vector<float>(count()));
    stripe.resize(projectors, std::vector<float>(count()));
    for (std::size_t p = 0; p < projectors; ++p) {
      truth.projectors.push_back({*algo::ImageView<std::uint8_t>::packed(mask[p], width, height),
                                  *algo::ImageView<float>::packed(u[p], width, height),
                                  *algo::ImageView<float>::packed(v[p], width, height),
                                  *algo::ImageView<float>::packed(stripe[p], width, height)});
    }
  }
  [[nodiscard]] std::size_t count() const {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  }
  [[nodiscard]] algo::RgbView view() { return *algo::RgbView::packed(image, width, height); }
  [[nodiscard]] const Rgb8& px(int x, int y) const { return image[at(x, y, width)]; }

  int width;
  int height;
  std::vector<Rgb8> image;
  std::vector<float> depth;
  std::vector<std::array<float, 3>> normal;
  std::vector<std::vector<std::uint8_t>> mask;
  std::vector<std::vector<float>> u;
  std::vector<std::vector<float>> v;
  std::vector<std::vector<float>> stripe;
  GroundTruthViews truth;  // views into the vectors above (their buffers survive a move)
};

std::unique_ptr<Renderer> makeRenderer(const algo::Rig& rig, const Scene& scene) {
  auto r = Renderer::create(rig, scene);
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error());
  return r ? std::move(*r) : nullptr;
}

FrameRequest request(const algo::Rig& rig, std::vector<bool> lit = {}, std::uint64_t seed = 1) {
  FrameRequest r;
  r.lit = lit.empty() ? std::vector<bool>(rig.projectors.size(), true) : std::move(lit);
  r.seed = seed;
  return r;
}

Frame renderFrame(Renderer& renderer, const algo::Rig& rig, const FrameRequest& req) {
  Frame f(rig.cameras[static_cast<std::size_t>(req.camera)], rig.projectors.size());
  const auto ok = renderer.render(req, f.view(), &f.truth);
  EXPECT_TRUE(ok.has_value()) << (ok ? "" : ok.error());
  return f;
}

// ---- Independent geometry ----

struct Ray {
  Vec3 o;
  Vec3 d;
};

Ray cameraRay(const algo::DeviceModel& camera, int x, int y) {
  const auto r = algo::lens::pixelRay(camera, {static_cast<double>(x), static_cast<double>(y)});
  EXPECT_TRUE(r.has_value());
  return {{r->origin[0], r->origin[1], r->origin[2]},
          {r->direction[0], r->direction[1], r->direction[2]}};
}

using test::centreOf;
using test::projectPoint;
using test::stripeFormula;
using test::toDevice;

// Ray parameter of the first crossing with t > 0, every shape grown by `grow` metres (a negative
// value shrinks it): comparing grown and shrunk shapes marks rays too close to an edge to judge.
using HitFn = std::function<std::optional<double>(const Ray&, double grow)>;

HitFn rectangle(const Pose& pose, double w, double h) {
  return [=](const Ray& r, double grow) -> std::optional<double> {
    const Vec3 n = pose.R.col(2);
    const double t = n.dot(pose.t - r.o) / n.dot(r.d);
    const Vec3 local = pose.R.transpose() * (r.o + t * r.d - pose.t);  // metres, unscaled
    if (t > 0.0 && std::abs(local.x()) <= pose.scale * w / 2 + grow &&
        std::abs(local.y()) <= pose.scale * h / 2 + grow) {
      return t;
    }
    return std::nullopt;
  };
}

HitFn ball(const Vec3& centre, double radius) {
  return [=](const Ray& r, double grow) -> std::optional<double> {
    // Distance along the ray to the point nearest the centre, and the chord's half length.
    const double along = r.d.dot(centre - r.o);
    const double miss2 = (centre - r.o - along * r.d).squaredNorm();
    const double rr = (radius + grow) * (radius + grow);
    if (miss2 > rr) {
      return std::nullopt;
    }
    const double t = along - std::sqrt(rr - miss2);
    return t > 0.0 ? std::optional<double>(t) : std::nullopt;
  };
}

// Entry and exit parameters of a ray through a box (world units, local frame of the pose).
std::optional<std::array<double, 2>> slabs(const Pose& pose, const Vec3& size, const Ray& r,
                                           double grow) {
  const Vec3 o = pose.R.transpose() * (r.o - pose.t);
  const Vec3 d = pose.R.transpose() * r.d;
  double enter = -std::numeric_limits<double>::infinity();
  double leave = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const double half = pose.scale * size[a] / 2 + grow;
    const double t1 = (-half - o[a]) / d[a];
    const double t2 = (half - o[a]) / d[a];
    enter = std::max(enter, std::min(t1, t2));
    leave = std::min(leave, std::max(t1, t2));
  }
  if (enter > leave) {
    return std::nullopt;
  }
  return std::array<double, 2>{enter, leave};
}

HitFn box(const Pose& pose, const Vec3& size) {
  return [=](const Ray& r, double grow) -> std::optional<double> {
    const auto s = slabs(pose, size, r, grow);
    return s && (*s)[0] > 0.0 ? std::optional<double>((*s)[0]) : std::nullopt;
  };
}

HitFn cylinder(const Pose& pose, double radius, double height) {
  return [=](const Ray& r, double grow) -> std::optional<double> {
    const Vec3 o = pose.R.transpose() * (r.o - pose.t);
    const Vec3 d = pose.R.transpose() * r.d;
    const double rad = pose.scale * radius + grow;
    const double half = pose.scale * height / 2 + grow;
    std::optional<double> best;
    const auto keep = [&](double t) {
      if (t > 0.0 && (!best || t < *best)) {
        best = t;
      }
    };
    // Side: (ox + t dx)² + (oz + t dz)² = rad².
    const double a = d.x() * d.x() + d.z() * d.z();
    const double b = o.x() * d.x() + o.z() * d.z();
    const double c = o.x() * o.x() + o.z() * o.z() - rad * rad;
    if (b * b - a * c >= 0.0) {
      for (const double sign : {-1.0, 1.0}) {
        const double t = (-b + sign * std::sqrt(b * b - a * c)) / a;
        if (std::abs(o.y() + t * d.y()) <= half) {
          keep(t);
        }
      }
    }
    for (const double y : {-half, half}) {
      const double t = (y - o.y()) / d.y();
      const Vec3 p = o + t * d;
      if (p.x() * p.x() + p.z() * p.z() <= rad * rad) {
        keep(t);
      }
    }
    return best;
  };
}

// The nearest crossing over all shapes; nullopt as "miss". `ambiguous` is set when shapes grown
// and shrunk by `margin` disagree (silhouettes, edges), where float ray casting may go either way.
std::optional<double> nearest(const std::vector<HitFn>& shapes, const Ray& r, double margin,
                              bool& ambiguous) {
  const auto first = [&](double grow) {
    std::optional<double> best;
    for (const auto& s : shapes) {
      const auto t = s(r, grow);
      if (t && (!best || *t < *best)) {
        best = t;
      }
    }
    return best;
  };
  const auto exact = first(0.0);
  const auto grown = first(margin);
  const auto shrunk = first(-margin);
  ambiguous = grown.has_value() != shrunk.has_value() ||
              (grown && std::abs(*grown - *shrunk) > 100.0 * margin);
  return exact;
}

// Every pixel centre: truth depth = analytic depth rounded to float, NaN where nothing is hit.
void expectDepthMatches(Renderer& renderer, const algo::Rig& rig, const std::vector<HitFn>& shapes,
                        int frame = 0, double turntableDeg = 0.0) {
  auto req = request(rig);
  req.frame = frame;
  req.turntableDeg = turntableDeg;
  const Frame f = renderFrame(renderer, rig, req);
  const auto& camera = rig.cameras[0];
  int hits = 0;
  int misses = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const Ray r = cameraRay(camera, x, y);
      bool ambiguous = false;
      const auto t = nearest(shapes, r, 1e-6, ambiguous);
      if (ambiguous) {
        continue;
      }
      const float depth = f.depth[at(x, y, f.width)];
      if (!t) {
        ++misses;
        EXPECT_TRUE(std::isnan(depth)) << "pixel " << x << "," << y;
        continue;
      }
      ++hits;
      // Required: 1e-6 relative. Delivered: the float nearest the analytic depth (half an ulp,
      // 2^-24 relative), which a float-only ray cast (~1e-7) would miss.
      const double z = toDevice(camera, r.o + *t * r.d).z();
      EXPECT_NEAR(depth, z, z * 0x1p-24 + 1e-12) << "pixel " << x << "," << y;
    }
  }
  EXPECT_GT(hits, f.width * f.height / 10);
  EXPECT_GT(misses, f.width * f.height / 10);
}

void expectDepthMatches(const algo::Rig& rig, const Scene& scene,
                        const std::vector<HitFn>& shapes) {
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  expectDepthMatches(*renderer, rig, shapes);
}

Mesh rectangleMesh(float halfWidth, float halfHeight) {
  Mesh mesh;
  mesh.path = "rectangle";
  mesh.vertices = {{-halfWidth, -halfHeight, 0.0F},
                   {halfWidth, -halfHeight, 0.0F},
                   {halfWidth, halfHeight, 0.0F},
                   {-halfWidth, halfHeight, 0.0F}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

algo::Rig smallRig(const std::string& name, int factor) {
  algo::Rig rig = exampleRig(name);
  if (!rig.cameras.empty()) {
    shrink(rig.cameras[0], factor);
  }
  return rig;
}

// ---- Depth ----

TEST(RenderDepth, FrontoParallelPlaneMatchesAnalytic) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.objects.push_back(makeObject(Plane{0.5, 0.3}, Mat3::Identity(), {0.05, -0.02, 0.9}));
  expectDepthMatches(rig, scene, {rectangle(scene.objects[0].pose, 0.5, 0.3)});
}

TEST(RenderDepth, TiltedScaledPlaneMatchesAnalytic) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.objects.push_back(
      makeObject(Plane{0.25, 0.2}, rotation(20.0, -35.0, 10.0), {-0.03, 0.04, 0.8}, 1.6));
  expectDepthMatches(rig, scene, {rectangle(scene.objects[0].pose, 0.25, 0.2)});
}

TEST(RenderDepth, SphereMatchesAnalyticAndNormalsFaceCamera) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  const Vec3 centre{0.04, -0.03, 0.85};
  scene.objects.push_back(makeObject(Sphere{0.1}, rotation(10, 20, 30), centre, 1.5));
  expectDepthMatches(rig, scene, {ball(centre, 0.15)});

  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  const Frame f = renderFrame(*renderer, rig, request(rig));
  int checked = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const float depth = f.depth[at(x, y, f.width)];
      if (std::isnan(depth)) {
        continue;
      }
      const Ray r = cameraRay(rig.cameras[0], x, y);
      const Vec3 p = r.o + r.d * (depth / r.d.z());
      const Vec3 expected = (p - centre).normalized();
      const auto& n = f.normal[at(x, y, f.width)];
      EXPECT_NEAR(n[0], expected.x(), 1e-4);
      EXPECT_NEAR(n[1], expected.y(), 1e-4);
      EXPECT_NEAR(n[2], expected.z(), 1e-4);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(RenderDepth, BoxAndCappedCylinderMatchAnalytic) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.objects.push_back(
      makeObject(Box{{0.12, 0.08, 0.1}}, rotation(25, 35, 10), {-0.12, 0.0, 0.8}));
  scene.objects.push_back(
      makeObject(Cylinder{0.05, 0.15, true}, rotation(-40, 0, 20), {0.12, 0.02, 0.8}, 1.2));
  expectDepthMatches(
      rig, scene,
      {box(scene.objects[0].pose, {0.12, 0.08, 0.1}), cylinder(scene.objects[1].pose, 0.05, 0.15)});
}

TEST(RenderDepth, TriangleMeshIsRefinedInDouble) {
  // Two triangles making a 0.4 × 0.3 rectangle; its depth must match the analytic plane, which a
  // float-only intersection would miss by ~1e-7 relative.
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.objects.push_back(
      makeObject(rectangleMesh(0.2F, 0.15F), rotation(-15, 25, 5), {0.02, 0.01, 0.95}, 1.3));
  expectDepthMatches(rig, scene, {rectangle(scene.objects[0].pose, 0.4, 0.3)});
}

TEST(RenderDepth, MovingObjectsFollowTheirMotionPerFrame) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  // The same rectangle as an analytic plane (user geometry) and as a mesh (Embree instance).
  for (const Shape& shape : {Shape{Plane{0.4, 0.3}}, Shape{rectangleMesh(0.2F, 0.15F)}}) {
    Scene scene = quietScene();
    Object o = makeObject(shape, Mat3::Identity(), {0.0, 0.0, 0.9});
    o.motion.velocityMPerFrame = {0.01, 0.0, 0.02};
    o.motion.axis = Vec3::UnitY();
    o.motion.angularDegPerFrame = 6.0;
    o.motion.pivot = {0.1, 0.0, 0.9};
    scene.objects.push_back(o);
    // scene.hpp, frame 3: turn 18° about y through the pivot, then move by 3 · velocity.
    const Mat3 turn = rotation(0.0, 18.0, 0.0);
    Pose moved;
    moved.R = turn;
    moved.t =
        turn * (o.pose.t - o.motion.pivot) + o.motion.pivot + 3.0 * o.motion.velocityMPerFrame;
    auto renderer = makeRenderer(rig, scene);
    ASSERT_NE(renderer, nullptr);
    expectDepthMatches(*renderer, rig, {rectangle(moved, 0.4, 0.3)}, 3);
    expectDepthMatches(*renderer, rig, {rectangle(o.pose, 0.4, 0.3)}, 0);
    expectDepthMatches(*renderer, rig, {rectangle(moved, 0.4, 0.3)}, 3);
  }
}

// The scene's turntable turns the objects standing on it, right-handed about its axis (up, -y)
// through its pivot; the wall does not turn. Positions worked out by hand: seen from above, a
// right-handed turn about "up" is counter-clockwise and takes +x towards +z.
TEST(RenderDepth, TurntableObjectsTurnAboutTheAxisThroughThePivot) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  const Vec3 pivot{0.0, 0.0, 0.9};
  Scene scene = quietScene();
  scene.turntable = TurntableMount{.axis = {0.0, -2.0, 0.0}, .pivot = pivot};
  Object ball0 = makeObject(Sphere{0.05}, Mat3::Identity(), pivot + Vec3{0.1, 0.0, 0.0});
  ball0.onTurntable = true;
  scene.objects.push_back(ball0);
  scene.objects.push_back(makeObject(Plane{0.8, 0.5}, Mat3::Identity(), {0.0, 0.0, 1.2}));
  const HitFn wall = rectangle(scene.objects[1].pose, 0.8, 0.5);
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  expectDepthMatches(*renderer, rig, {ball(pivot + Vec3{0.1, 0.0, 0.0}, 0.05), wall}, 0, 0.0);
  expectDepthMatches(*renderer, rig, {ball(pivot + Vec3{0.0, 0.0, 0.1}, 0.05), wall}, 0, 90.0);
  expectDepthMatches(*renderer, rig, {ball(pivot + Vec3{0.0, 0.0, -0.1}, 0.05), wall}, 0, -90.0);
  expectDepthMatches(*renderer, rig, {ball(pivot + Vec3{-0.1, 0.0, 0.0}, 0.05), wall}, 5, 180.0);

  // A mesh (an Embree instance) turns its orientation too: 30 degrees, its centre from
  // (-0.1, 0, 0) to (-0.1·cos 30°, 0, -0.1·sin 30°) off the pivot, its face turned with it.
  Scene flat = quietScene();
  flat.turntable = TurntableMount{.axis = {0.0, -1.0, 0.0}, .pivot = pivot};
  Object card =
      makeObject(rectangleMesh(0.15F, 0.15F), Mat3::Identity(), pivot + Vec3{-0.1, 0.0, 0.0});
  card.onTurntable = true;
  flat.objects.push_back(card);
  auto cardRenderer = makeRenderer(rig, flat);
  ASSERT_NE(cardRenderer, nullptr);
  Pose turned;
  turned.R = rotation(0.0, -30.0, 0.0);
  turned.t = pivot + Vec3{-0.1 * std::cos(std::numbers::pi / 6), 0.0,
                          -0.1 * std::sin(std::numbers::pi / 6)};
  expectDepthMatches(*cardRenderer, rig, {rectangle(turned, 0.3, 0.3)}, 0, 30.0);
  expectDepthMatches(*cardRenderer, rig, {rectangle(card.pose, 0.3, 0.3)}, 0, 0.0);
}

// ---- Projector ground truth ----

TEST(RenderTruth, ReprojectionGivesProjectorCoordinatesAndStripe) {
  const algo::Rig rig = smallRig("rig_3proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.objects.push_back(wall(0.9));
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  const Frame f = renderFrame(*renderer, rig, request(rig, {false, false, false}));
  const auto& camera = rig.cameras[0];
  const auto plane = rectangle(scene.objects[0].pose, 3.0, 3.0);
  const auto floatTolerance = [](double value) { return 1e-6 + std::abs(value) * 0x1p-24; };
  std::vector<int> lit(rig.projectors.size(), 0);
  std::vector<int> unlit(rig.projectors.size(), 0);
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const std::size_t i = at(x, y, f.width);
      const Ray r = cameraRay(camera, x, y);
      const auto t = plane(r, 0.0);
      ASSERT_TRUE(t.has_value());
      const Vec3 exact = r.o + *t * r.d;
      // The point as a user reconstructs it from the (float) depth and the pixel's ray.
      const Vec3 fromDepth = r.o + r.d * (f.depth[i] / r.d.z());
      for (std::size_t p = 0; p < rig.projectors.size(); ++p) {
        const auto& proj = rig.projectors[p];
        const auto uv = projectPoint(proj, exact);
        ASSERT_TRUE(uv.has_value());
        const auto [u, v] = *uv;
        const double edge =
            std::min({u + 0.5, proj.width - 0.5 - u, v + 0.5, proj.height - 0.5 - v});
        if (std::abs(edge) < 1e-6) {
          continue;
        }
        if (edge < 0.0) {
          ++unlit[p];
          EXPECT_EQ(f.mask[p][i], 0);
          EXPECT_TRUE(std::isnan(f.u[p][i]) && std::isnan(f.v[p][i]) && std::isnan(f.stripe[p][i]));
          continue;
        }
        ++lit[p];
        ASSERT_EQ(f.mask[p][i], 255) << "projector " << p << " pixel " << x << "," << y;
        EXPECT_NEAR(f.u[p][i], u, floatTolerance(u));
        EXPECT_NEAR(f.v[p][i], v, floatTolerance(v));
        const double s = stripeFormula(proj, u, v);
        EXPECT_NEAR(f.stripe[p][i], s, floatTolerance(s));
        // Through the float depth: ~1e-7 relative in the point, ~1e-4 px in the projector.
        const auto back = projectPoint(proj, fromDepth);
        ASSERT_TRUE(back.has_value());
        EXPECT_NEAR(f.u[p][i], (*back)[0], 1e-3);
        EXPECT_NEAR(f.v[p][i], (*back)[1], 1e-3);
      }
    }
  }
  for (std::size_t p = 0; p < rig.projectors.size(); ++p) {
    EXPECT_GT(lit[p], f.width * f.height / 2) << "projector " << p;
    EXPECT_GT(unlit[p], 0) << "projector " << p;
  }
}

TEST(RenderShadow, OccluderShadowsOneProjectorWhileTheOtherStillLights) {
  // A small box between the projectors and a wall: each projector casts its own shadow of it.
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.objects.push_back(wall(1.0));
  const Vec3 boxSize{0.06, 0.06, 0.06};
  scene.objects.push_back(makeObject(Box{boxSize}, rotation(0, 10, 0), {0.0, 0.0, 0.6}));
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  const Frame f = renderFrame(*renderer, rig, request(rig));

  const auto& camera = rig.cameras[0];
  const auto plane = rectangle(scene.objects[0].pose, 3.0, 3.0);
  const auto occluder = box(scene.objects[1].pose, boxSize);
  constexpr double kMargin = 1e-4;  // > the renderer's 1e-5 m shadow-ray offset
  std::vector<int> shadowed(2, 0);
  int shadowedByFirstOnly = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const Ray r = cameraRay(camera, x, y);
      if (occluder(r, kMargin)) {
        continue;  // the box itself, or too close to its silhouette
      }
      const Vec3 p = r.o + *plane(r, 0.0) * r.d;
      const std::size_t i = at(x, y, f.width);
      std::array<bool, 2> inShadow{};
      bool judged = true;
      for (std::size_t k = 0; k < 2; ++k) {
        const Vec3 c = centreOf(rig.projectors[k]);
        const Ray toProjector{p, (c - p).normalized()};
        const double length = (c - p).norm();
        const auto blocks = [&](double grow) {
          const auto s = slabs(scene.objects[1].pose, boxSize, toProjector, grow);
          return s && std::max((*s)[0], 0.0) <= std::min((*s)[1], length);
        };
        if (blocks(kMargin) != blocks(-kMargin)) {
          judged = false;
          break;
        }
        const auto uv = projectPoint(rig.projectors[k], p);
        inShadow[k] = blocks(0.0);
        const bool inImage = uv && (*uv)[0] > -0.5 && (*uv)[0] < rig.projectors[k].width - 0.5 &&
                             (*uv)[1] > -0.5 && (*uv)[1] < rig.projectors[k].height - 0.5;
        if (!inImage) {
          judged = false;
          break;
        }
      }
      if (!judged) {
        continue;
      }
      for (std::size_t k = 0; k < 2; ++k) {
        EXPECT_EQ(f.mask[k][i], inShadow[k] ? 0 : 255)
            << "projector " << k << " pixel " << x << "," << y;
        shadowed[k] += inShadow[k] ? 1 : 0;
      }
      shadowedByFirstOnly += inShadow[0] && !inShadow[1] && f.mask[1][i] == 255 ? 1 : 0;
    }
  }
  EXPECT_GT(shadowed[0], 100);
  EXPECT_GT(shadowed[1], 100);
  EXPECT_GT(shadowedByFirstOnly, 100);
}

// ---- Image formation ----

TEST(RenderImage, PatternColoursAppearWhereGeometryPredicts) {
  algo::Rig rig = exampleRig("rig_3proj_1cam.json");
  crop(rig.cameras[0], 224, 168, 192, 144);  // full-resolution stripes (~4.5 px), fewer pixels
  Scene scene = quietScene();
  scene.supersampling = 2;
  scene.objects.push_back(wall(0.9));
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  for (std::size_t p = 0; p < rig.projectors.size(); ++p) {
    std::vector<bool> lit(rig.projectors.size(), false);
    lit[p] = true;
    const Frame f = renderFrame(*renderer, rig, request(rig, lit));
    int checked = 0;
    for (std::size_t i = 0; i < f.count(); ++i) {
      const double s = f.stripe[p][i];
      if (!(s >= 0.0 && s < algo::stripe::kStripes)) {
        continue;
      }
      const double frac = s - std::floor(s);
      if (frac < 0.3 || frac > 0.7) {
        continue;  // within 0.3 stripe of a boundary
      }
      const auto colour = algo::stripe::kSequence[static_cast<std::size_t>(s)];
      const std::array<int, 3> rgb = {f.image[i].r, f.image[i].g, f.image[i].b};
      const auto dominant = std::max_element(rgb.begin(), rgb.end()) - rgb.begin();
      ASSERT_EQ(dominant, algo::stripe::indexOf(colour)) << "projector " << p << " pixel " << i;
      EXPECT_GT(rgb[static_cast<std::size_t>(dominant)], 100);
      ++checked;
    }
    EXPECT_GT(checked, 5000) << "projector " << p;
  }
}

TEST(RenderImage, RadiometryFollowsCosineFalloffAmbientAlbedoCrosstalkAndGain) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.objects.push_back(wall(1.1));
  scene.objects[0].albedo.rgb = {0.9, 0.6, 0.7};
  scene.lighting.ambient = {0.05, 0.1, 0.15};
  scene.lighting.projectorPower = 0.7;
  scene.lighting.inverseSquare = true;
  scene.lighting.referenceDistanceM = 0.9;
  scene.camera.gain = 0.8;
  scene.camera.crosstalk << 0.9, 0.1, 0.0, 0.05, 0.85, 0.1, 0.0, 0.15, 0.8;
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  const Frame f = renderFrame(*renderer, rig, request(rig, {true, false}));

  const auto& proj = rig.projectors[0];
  const Vec3 c = centreOf(proj);
  const auto plane = rectangle(scene.objects[0].pose, 3.0, 3.0);
  const Vec3 albedo = scene.objects[0].albedo.rgb;
  int lit = 0;
  int dark = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const Ray r = cameraRay(rig.cameras[0], x, y);
      const Vec3 p = r.o + *plane(r, 0.0) * r.d;
      Vec3 irradiance = scene.lighting.ambient;
      const auto uv = projectPoint(proj, p);
      const double s = uv ? stripeFormula(proj, (*uv)[0], (*uv)[1]) : kNaN;
      const bool inImage = uv && (*uv)[0] > -0.5 && (*uv)[0] < proj.width - 0.5 &&
                           (*uv)[1] > -0.5 && (*uv)[1] < proj.height - 0.5;
      if (inImage && s >= 0.0 && s < algo::stripe::kStripes) {
        const double frac = s - std::floor(s);
        if (frac < 0.2 || frac > 0.8) {
          continue;  // the projector pixel may be either stripe
        }
        const double d = (c - p).norm();
        const double cosTheta = Vec3(0, 0, -1).dot(c - p) / d;
        const double w = 0.7 * cosTheta * (0.9 / d) * (0.9 / d);
        irradiance[algo::stripe::indexOf(algo::stripe::kSequence[static_cast<std::size_t>(s)])] +=
            w;
        ++lit;
      } else if (!inImage) {
        ++dark;
      } else {
        continue;
      }
      const Vec3 grey = 0.8 * 255.0 * scene.camera.crosstalk * albedo.cwiseProduct(irradiance);
      const Rgb8 px = f.px(x, y);
      EXPECT_NEAR(px.r, std::clamp(grey.x(), 0.0, 255.0), 0.5 + 1e-4) << x << "," << y;
      EXPECT_NEAR(px.g, std::clamp(grey.y(), 0.0, 255.0), 0.5 + 1e-4) << x << "," << y;
      EXPECT_NEAR(px.b, std::clamp(grey.z(), 0.0, 255.0), 0.5 + 1e-4) << x << "," << y;
    }
  }
  EXPECT_GT(lit, 2000);
  EXPECT_GT(dark, 50);
}

// Calls visit(x, y, local point) for each pixel of cam0 whose centre ray meets the w × h
// rectangle at pose away from its edges (alone in the scene).
template <class Visit>
void forEachPixelOnRectangle(const algo::Rig& rig, const Pose& pose, double w, double h,
                             Visit visit) {
  const auto plane = rectangle(pose, w, h);
  const auto& camera = rig.cameras[0];
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Ray r = cameraRay(camera, x, y);
      bool ambiguous = false;
      const auto t = nearest({plane}, r, 1e-5, ambiguous);
      if (t && !ambiguous) {
        visit(x, y, Vec3(pose.R.transpose() * (r.o + *t * r.d - pose.t)));
      }
    }
  }
}

TEST(RenderImage, CheckerAlbedoFollowsObjectLocalCoordinates) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.lighting.ambient = {1.0, 1.0, 1.0};
  Object o = makeObject(Plane{0.6, 0.45}, rotation(15, -20, 30), {0.02, 0.0, 0.9});
  const CheckerTexture checker;  // the default RGBCMY panel
  o.albedo.texture = checker;
  scene.objects.push_back(o);
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  const Frame f = renderFrame(*renderer, rig, request(rig, {false, false}));
  int checked = 0;
  forEachPixelOnRectangle(rig, o.pose, 0.6, 0.45, [&](int x, int y, const Vec3& local) {
    const double cx = local.x() / checker.squareM;
    const double cy = local.y() / checker.squareM;
    if (std::abs(cx - std::round(cx)) < 1e-3 || std::abs(cy - std::round(cy)) < 1e-3) {
      return;  // on a square edge
    }
    const auto k = static_cast<long>(std::floor(cx) + std::floor(cy));
    const Vec3& colour = checker.colours[static_cast<std::size_t>(((k % 6) + 6) % 6)];
    const Rgb8 expected{static_cast<std::uint8_t>(255 * colour.x()),
                        static_cast<std::uint8_t>(255 * colour.y()),
                        static_cast<std::uint8_t>(255 * colour.z())};
    EXPECT_EQ(f.px(x, y), expected) << "pixel " << x << "," << y;
    ++checked;
  });
  EXPECT_GT(checked, 1000);
}

TEST(RenderImage, CameraDefocusIsAGaussianBlurOfTheLinearImage) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.objects.push_back(wall(0.9));
  auto sharpRenderer = makeRenderer(rig, scene);
  constexpr double kSigma = 1.3;
  scene.camera.defocusSigmaPx = kSigma;
  auto blurRenderer = makeRenderer(rig, scene);
  ASSERT_NE(sharpRenderer, nullptr);
  ASSERT_NE(blurRenderer, nullptr);
  const Frame sharp = renderFrame(*sharpRenderer, rig, request(rig, {true, false}));
  const Frame blurred = renderFrame(*blurRenderer, rig, request(rig, {true, false}));
  // Separable Gaussian, taps to ±⌈4σ⌉, edge pixels repeated beyond the border.
  const int radius = static_cast<int>(std::ceil(4 * kSigma));
  double sum = 0.0;
  for (int k = -radius; k <= radius; ++k) {
    sum += std::exp(-0.5 * k * k / (kSigma * kSigma));
  }
  int maxChange = 0;
  for (int y = 0; y < sharp.height; ++y) {
    for (int x = 0; x < sharp.width; ++x) {
      std::array<double, 3> acc{};
      for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
          const double w = std::exp(-0.5 * (dx * dx + dy * dy) / (kSigma * kSigma)) / (sum * sum);
          const Rgb8 s = sharp.px(std::clamp(x + dx, 0, sharp.width - 1),
                                  std::clamp(y + dy, 0, sharp.height - 1));
          acc[0] += w * s.r;
          acc[1] += w * s.g;
          acc[2] += w * s.b;
        }
      }
      const Rgb8 b = blurred.px(x, y);
      // The sharp image was rounded to 8 bits before this blur: ±0.5, plus the final rounding.
      EXPECT_NEAR(b.r, acc[0], 1.0);
      EXPECT_NEAR(b.g, acc[1], 1.0);
      EXPECT_NEAR(b.b, acc[2], 1.0);
      maxChange = std::max({maxChange, std::abs(b.r - sharp.px(x, y).r),
                            std::abs(b.g - sharp.px(x, y).g), std::abs(b.b - sharp.px(x, y).b)});
    }
  }
  EXPECT_GT(maxChange, 20);
}

TEST(RenderImage, ImageTextureRepeatsInObjectLocalCoordinates) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.lighting.ambient = {1.0, 1.0, 1.0};
  ImageTexture texture;
  texture.path = "in-memory";
  texture.widthM = 0.1;
  texture.heightM = 0.08;
  texture.width = 3;
  texture.height = 2;
  texture.texels = {{0.2F, 0.5F, 0.9F}, {0.9F, 0.1F, 0.3F}, {0.4F, 0.4F, 0.0F},
                    {0.0F, 0.7F, 0.6F}, {1.0F, 1.0F, 1.0F}, {0.3F, 0.0F, 0.8F}};
  Object o = makeObject(Plane{0.5, 0.4}, rotation(-10, 15, -25), {-0.02, 0.01, 0.85});
  o.albedo.texture = texture;
  scene.objects.push_back(o);
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  const Frame f = renderFrame(*renderer, rig, request(rig, {false, false}));
  int checked = 0;
  forEachPixelOnRectangle(rig, o.pose, 0.5, 0.4, [&](int x, int y, const Vec3& local) {
    // The image spans [−w/2, w/2] × [−h/2, h/2] of local x, y, row 0 at −h/2, and repeats.
    const double cu = (local.x() / texture.widthM + 0.5) * texture.width;
    const double cv = (local.y() / texture.heightM + 0.5) * texture.height;
    if (std::abs(cu - std::round(cu)) < 1e-3 || std::abs(cv - std::round(cv)) < 1e-3) {
      return;  // on a texel edge
    }
    const auto col = ((static_cast<long>(std::floor(cu)) % 3) + 3) % 3;
    const auto row = ((static_cast<long>(std::floor(cv)) % 2) + 2) % 2;
    const auto& texel = texture.texels[static_cast<std::size_t>(row * 3 + col)];
    const Rgb8 px = f.px(x, y);
    EXPECT_NEAR(px.r, 255.0 * texel[0], 0.5 + 1e-4) << x << "," << y;
    EXPECT_NEAR(px.g, 255.0 * texel[1], 0.5 + 1e-4) << x << "," << y;
    EXPECT_NEAR(px.b, 255.0 * texel[2], 0.5 + 1e-4) << x << "," << y;
    ++checked;
  });
  EXPECT_GT(checked, 2000);
}

TEST(RenderImage, ProjectorDefocusBlursThePatternInProjectorPixels) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = quietScene();
  scene.objects.push_back(wall(0.9));
  constexpr double kSigma = 2.0;
  scene.lighting.projectorDefocusSigmaPx = kSigma;
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  const Frame f = renderFrame(*renderer, rig, request(rig, {true, false}));

  const auto& proj = rig.projectors[0];
  const Vec3 c = centreOf(proj);
  const auto plane = rectangle(scene.objects[0].pose, 3.0, 3.0);
  // The pattern at each projector pixel centre (docs/pattern.md); black outside the image.
  std::vector<Vec3> image(static_cast<std::size_t>(proj.width) *
                          static_cast<std::size_t>(proj.height));
  for (int v = 0; v < proj.height; ++v) {
    for (int u = 0; u < proj.width; ++u) {
      const double s = stripeFormula(proj, u, v);
      Vec3& rgb = image[at(u, v, proj.width)];
      rgb.setZero();
      if (s >= 0.0 && s < algo::stripe::kStripes) {
        rgb[algo::stripe::indexOf(algo::stripe::kSequence[static_cast<std::size_t>(s)])] = 1.0;
      }
    }
  }
  const auto pattern = [&](long u, long v) {
    return u >= 0 && v >= 0 && u < proj.width && v < proj.height
               ? image[at(static_cast<int>(u), static_cast<int>(v), proj.width)]
               : Vec3::Zero().eval();
  };
  const int radius = static_cast<int>(std::ceil(4 * kSigma));
  double sum = 0.0;
  for (int k = -radius; k <= radius; ++k) {
    sum += std::exp(-0.5 * k * k / (kSigma * kSigma));
  }
  int checked = 0;
  int mixed = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const Ray r = cameraRay(rig.cameras[0], x, y);
      const Vec3 p = r.o + *plane(r, 0.0) * r.d;
      const auto uv = projectPoint(proj, p);
      if (!uv || std::abs((*uv)[0] - std::floor((*uv)[0]) - 0.5) < 1e-6 ||
          std::abs((*uv)[1] - std::floor((*uv)[1]) - 0.5) < 1e-6) {
        continue;  // exactly between two projector pixels
      }
      const long u0 = std::lround((*uv)[0]);
      const long v0 = std::lround((*uv)[1]);
      if (u0 < 0 || v0 < 0 || u0 >= proj.width || v0 >= proj.height) {
        continue;
      }
      Vec3 light = Vec3::Zero();
      for (int dv = -radius; dv <= radius; ++dv) {
        for (int du = -radius; du <= radius; ++du) {
          const double w = std::exp(-0.5 * (du * du + dv * dv) / (kSigma * kSigma)) / (sum * sum);
          light += w * pattern(u0 + du, v0 + dv);
        }
      }
      const double cosTheta = Vec3(0, 0, -1).dot((c - p).normalized());
      const Vec3 grey = 255.0 * 0.8 * scene.lighting.projectorPower * cosTheta * light;
      const Rgb8 px = f.px(x, y);
      EXPECT_NEAR(px.r, grey.x(), 0.5 + 1e-3) << x << "," << y;
      EXPECT_NEAR(px.g, grey.y(), 0.5 + 1e-3) << x << "," << y;
      EXPECT_NEAR(px.b, grey.z(), 0.5 + 1e-3) << x << "," << y;
      ++checked;
      mixed += (grey.array() > 20.0).count() >= 2 ? 1 : 0;
    }
  }
  EXPECT_GT(checked, f.width * f.height / 2);
  EXPECT_GT(mixed, 500);
}

TEST(RenderNoise, StandardDeviationOnAFlatPatchMatchesSigma) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 2);  // 320 × 240
  Scene scene = quietScene();
  scene.objects.push_back(wall(0.9));
  scene.lighting.ambient = {0.5, 0.5, 0.5};
  scene.camera.noiseSigma = {1.8138, 1.2923, 1.6745};
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  const Frame f = renderFrame(*renderer, rig, request(rig, {false, false}, 42));
  std::array<double, 3> sum{};
  std::array<double, 3> sum2{};
  for (const Rgb8& px : f.image) {
    const std::array<double, 3> c = {static_cast<double>(px.r), static_cast<double>(px.g),
                                     static_cast<double>(px.b)};
    for (std::size_t k = 0; k < 3; ++k) {
      sum[k] += c[k];
      sum2[k] += c[k] * c[k];
    }
  }
  const auto n = static_cast<double>(f.image.size());
  for (std::size_t k = 0; k < 3; ++k) {
    const double mean = sum[k] / n;
    const double sd = std::sqrt(sum2[k] / n - mean * mean);
    const double sigma = scene.camera.noiseSigma[static_cast<Eigen::Index>(k)];
    EXPECT_NEAR(mean, 0.5 * 0.8 * 255.0, 0.05) << "channel " << k;
    EXPECT_NEAR(sd / sigma, 1.0, 0.05) << "channel " << k;
  }
}

Scene busyScene() {
  Scene scene;  // default noise, ambient and supersampling
  scene.objects.push_back(wall(1.0));
  scene.objects.push_back(makeObject(Sphere{0.08}, Mat3::Identity(), {0.03, 0.02, 0.8}));
  return scene;
}

TEST(RenderDeterminism, SameRequestSameImageOtherSeedDiffers) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  auto renderer = makeRenderer(rig, busyScene());
  ASSERT_NE(renderer, nullptr);
  const Frame a = renderFrame(*renderer, rig, request(rig, {}, 7));
  const Frame b = renderFrame(*renderer, rig, request(rig, {}, 7));
  const Frame c = renderFrame(*renderer, rig, request(rig, {}, 8));
  EXPECT_EQ(a.image, b.image);
  EXPECT_EQ(std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)), 0);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.image.size(); ++i) {
    differing += a.image[i] == c.image[i] ? 0U : 1U;
  }
  EXPECT_GT(differing, a.image.size() / 2);
}

TEST(RenderLit, ProjectorThatIsOffContributesNothing) {
  const algo::Rig both = smallRig("rig_2proj_1cam.json", 4);
  algo::Rig onlyFirst = both;
  onlyFirst.projectors.pop_back();
  auto renderer = makeRenderer(both, busyScene());
  auto reference = makeRenderer(onlyFirst, busyScene());
  ASSERT_NE(renderer, nullptr);
  ASSERT_NE(reference, nullptr);
  const Frame firstOn = renderFrame(*renderer, both, request(both, {true, false}, 3));
  const Frame bothOn = renderFrame(*renderer, both, request(both, {true, true}, 3));
  const Frame alone = renderFrame(*reference, onlyFirst, request(onlyFirst, {true}, 3));
  EXPECT_EQ(firstOn.image, alone.image);
  EXPECT_NE(bothOn.image, alone.image);
}

// The camera's exposure and gain and the projectors' power (the owner's settings) against the
// same light set in the scene instead: exposure and gain scale the signal, gain the read noise
// too, power the projectors' light alone.
TEST(RenderControls, ExposureGainAndPowerScaleTheLightAsTheSceneWould) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 4);
  Scene scene = busyScene();
  scene.lighting.projectorPower = 0.6;
  scene.camera.noiseSigma = {1.0, 1.5, 2.0};
  Scene equivalent = scene;
  equivalent.lighting.projectorPower = 0.6 * 0.5;
  equivalent.camera.gain = scene.camera.gain * 1.5 * 2.0;
  equivalent.camera.noiseSigma = 2.0 * scene.camera.noiseSigma;
  auto renderer = makeRenderer(rig, scene);
  auto reference = makeRenderer(rig, equivalent);
  ASSERT_NE(renderer, nullptr);
  ASSERT_NE(reference, nullptr);
  FrameRequest controlled = request(rig, {true, true}, 5);
  controlled.power = {0.5, 0.5};
  controlled.exposureScale = 1.5;
  controlled.gain = 2.0;
  const Frame got = renderFrame(*renderer, rig, controlled);
  const Frame want = renderFrame(*reference, rig, request(rig, {true, true}, 5));
  const Frame plain = renderFrame(*renderer, rig, request(rig, {true, true}, 5));
  ASSERT_EQ(got.image.size(), want.image.size());
  std::size_t offByOne = 0;
  std::size_t changed = 0;
  for (std::size_t i = 0; i < got.image.size(); ++i) {
    const std::array<int, 3> a = {got.image[i].r, got.image[i].g, got.image[i].b};
    const std::array<int, 3> b = {want.image[i].r, want.image[i].g, want.image[i].b};
    for (std::size_t c = 0; c < 3; ++c) {
      ASSERT_LE(std::abs(a[c] - b[c]), 1) << "pixel " << i;  // the products' rounding
      offByOne += a[c] == b[c] ? 0U : 1U;
    }
    changed += got.image[i] == plain.image[i] ? 0U : 1U;
  }
  EXPECT_LT(offByOne, got.image.size() * 3 / 1000);
  EXPECT_GT(changed, got.image.size() / 2);

  // One projector dimmed to nothing is that projector off.
  FrameRequest dimmed = request(rig, {true, true}, 5);
  dimmed.power = {1.0, 0.0};
  EXPECT_EQ(renderFrame(*renderer, rig, dimmed).image,
            renderFrame(*renderer, rig, request(rig, {true, false}, 5)).image);
}

// ---- Errors ----

TEST(RenderErrors, RejectsBadRequestsAndBuffers) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 8);
  Scene scene = quietScene();
  scene.objects.push_back(wall(1.0));
  auto renderer = makeRenderer(rig, scene);
  ASSERT_NE(renderer, nullptr);
  Frame f(rig.cameras[0], rig.projectors.size());

  std::vector<Rgb8> small(static_cast<std::size_t>((f.width - 1) * f.height));
  const auto wrongSize =
      renderer->render(request(rig), *algo::RgbView::packed(small, f.width - 1, f.height), nullptr);
  ASSERT_FALSE(wrongSize.has_value());
  EXPECT_NE(wrongSize.error().find("image"), std::string::npos) << wrongSize.error();

  for (const int camera : {-1, 1}) {
    auto req = request(rig);
    req.camera = camera;
    const auto bad = renderer->render(req, f.view(), nullptr);
    ASSERT_FALSE(bad.has_value());
    EXPECT_NE(bad.error().find("camera index"), std::string::npos) << bad.error();
  }
  for (const std::size_t n : {std::size_t{1}, std::size_t{3}}) {
    auto req = request(rig);
    req.lit.assign(n, true);
    const auto bad = renderer->render(req, f.view(), nullptr);
    ASSERT_FALSE(bad.has_value());
    EXPECT_NE(bad.error().find("lit"), std::string::npos) << bad.error();
  }

  GroundTruthViews truth = f.truth;
  truth.depth = truth.depth.sub(0, 0, f.width, f.height - 1);
  EXPECT_FALSE(renderer->render(request(rig), f.view(), &truth).has_value());
  truth = f.truth;
  truth.projectors.pop_back();
  EXPECT_FALSE(renderer->render(request(rig), f.view(), &truth).has_value());
  truth = f.truth;
  truth.projectors[1].stripe = truth.projectors[1].stripe.sub(1, 0, f.width, f.height);
  EXPECT_FALSE(renderer->render(request(rig), f.view(), &truth).has_value());

  // Empty views are skipped, not errors.
  truth = f.truth;
  truth.normal = {};
  truth.projectors[0].u = {};
  EXPECT_TRUE(renderer->render(request(rig), f.view(), &truth).has_value());
}

TEST(RenderErrors, RejectsEmptyMeshAndBadSupersampling) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 8);
  Scene scene = quietScene();
  Mesh empty;
  empty.path = "missing.ply";
  scene.objects.push_back(makeObject(empty, Mat3::Identity(), {0, 0, 1}));
  const auto noMesh = Renderer::create(rig, scene);
  ASSERT_FALSE(noMesh.has_value());
  EXPECT_NE(noMesh.error().find("empty"), std::string::npos) << noMesh.error();

  scene.objects.clear();
  scene.supersampling = 0;
  EXPECT_FALSE(Renderer::create(rig, scene).has_value());
}

// ---- One validation: the renderer draws what scene.json accepts and refuses the rest ----

// A plane facing the camera, written as scene.json with the given supersampling.
std::string planeSceneJson(int supersampling) {
  return R"({"format": "stripemux-scene/1", "supersampling": )" + std::to_string(supersampling) +
         R"(, "objects": [{"shape": {"type": "plane"}, "pose": {"t": [0, 0, 0.9]}}]})";
}

// Given the largest supersampling scene.json allows, when read and rendered, then it renders; one
// more is refused by the reader (naming the file and the field) and by the renderer, in the same
// words: the limit is one value.
TEST(RenderSceneRules, SupersamplingLimitIsOneValue) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 8);
  const auto atLimit = config::parseScene(planeSceneJson(kMaxSceneSupersampling), ".");
  ASSERT_TRUE(atLimit.has_value()) << atLimit.error().message();
  ASSERT_EQ(atLimit->supersampling, kMaxSceneSupersampling);
  auto renderer = makeRenderer(rig, *atLimit);
  ASSERT_NE(renderer, nullptr);
  const Frame f = renderFrame(*renderer, rig, request(rig));
  EXPECT_GT(f.px(f.width / 2, f.height / 2).r + f.px(f.width / 2, f.height / 2).g, 0);

  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / "smx_render_supersampling_over_limit.json";
  {
    std::ofstream out(file);
    out << planeSceneJson(kMaxSceneSupersampling + 1);
  }
  const auto overLimit = config::loadScene(file);
  std::filesystem::remove(file);
  ASSERT_FALSE(overLimit.has_value());
  EXPECT_EQ(overLimit.error().file, file.string());
  EXPECT_EQ(overLimit.error().field, "supersampling");
  EXPECT_EQ(overLimit.error().problem,
            "must be an integer from 1 to " + std::to_string(kMaxSceneSupersampling) +
                " (samples per pixel side), got " + std::to_string(kMaxSceneSupersampling + 1));

  Scene over = *atLimit;
  over.supersampling = kMaxSceneSupersampling + 1;
  const auto refused = Renderer::create(rig, over);
  ASSERT_FALSE(refused.has_value());
  EXPECT_EQ(refused.error(), "supersampling: " + overLimit.error().problem);
}

// Given scenes at and just beyond the edges of scene.json's value rules, when validated and given
// to the renderer, then the renderer accepts exactly the scenes validateScene() accepts and
// refuses the others with its message.
TEST(RenderSceneRules, RendererRefusesExactlyWhatTheValidatorRefuses) {
  const algo::Rig rig = smallRig("rig_2proj_1cam.json", 8);
  const auto base = [] {
    Scene s = quietScene();
    s.objects.push_back(makeObject(Sphere{0.1}, Mat3::Identity(), {0, 0, 0.9}));
    return s;
  };
  struct Case {
    const char* name;
    std::function<void(Scene&)> change;
    bool valid;
  };
  const std::vector<Case> cases = {
      {"as is", [](Scene&) {}, true},
      {"supersampling 1", [](Scene& s) { s.supersampling = 1; }, true},
      {"supersampling 0", [](Scene& s) { s.supersampling = 0; }, false},
      {"limit + 1", [](Scene& s) { s.supersampling = kMaxSceneSupersampling + 1; }, false},
      {"ambient 1", [](Scene& s) { s.lighting.ambient = Vec3::Ones(); }, true},
      {"ambient above 1 (saturating)", [](Scene& s) { s.lighting.ambient.y() = 1.5; }, true},
      {"ambient negative", [](Scene& s) { s.lighting.ambient.y() = -0.5; }, false},
      {"no inverse square, distance 0",
       [](Scene& s) {
         s.lighting.inverseSquare = false;
         s.lighting.referenceDistanceM = 0;
       },
       false},
      {"projector power 0", [](Scene& s) { s.lighting.projectorPower = 0; }, false},
      {"negative defocus", [](Scene& s) { s.camera.defocusSigmaPx = -0.5; }, false},
      {"gain NaN", [](Scene& s) { s.camera.gain = kNaN; }, false},
      {"negative crosstalk", [](Scene& s) { s.camera.crosstalk(0, 1) = -0.1; }, true},
      {"albedo 1", [](Scene& s) { s.objects[0].albedo.rgb = Vec3::Ones(); }, true},
      {"albedo above 1", [](Scene& s) { s.objects[0].albedo.rgb.x() = 1.01; }, false},
      {"radius 0", [](Scene& s) { s.objects[0].shape = Sphere{0.0}; }, false},
      {"reflection", [](Scene& s) { s.objects[0].pose.R(0, 0) = -1; }, false},
      {"scale 0", [](Scene& s) { s.objects[0].pose.scale = 0; }, false},
      {"still object, zero axis", [](Scene& s) { s.objects[0].motion.axis = Vec3::Zero(); }, false},
      {"turning, long axis",
       [](Scene& s) {
         s.objects[0].motion.axis = {0, 1e6, 0};
         s.objects[0].motion.angularDegPerFrame = 5;
       },
       true},
      {"no objects", [](Scene& s) { s.objects.clear(); }, false},
      {"empty mesh",
       [](Scene& s) {
         s.objects[0].shape = Mesh{"x.ply", {}, {}};
       },
       false},
      {"checker without colours",
       [](Scene& s) {
         s.objects[0].albedo.texture = CheckerTexture{0.04, {}};
       },
       false},
      {"texture not loaded",
       [](Scene& s) {
         ImageTexture notLoaded;
         notLoaded.path = "t.png";
         s.objects[0].albedo.texture = notLoaded;
       },
       false},
  };
  for (const auto& c : cases) {
    Scene scene = base();
    c.change(scene);
    const auto valid = config::validateScene(scene);
    EXPECT_EQ(valid.has_value(), c.valid) << c.name;
    const auto renderer = Renderer::create(rig, scene);
    ASSERT_EQ(renderer.has_value(), valid.has_value())
        << c.name << ": " << (renderer ? valid.error().message() : renderer.error());
    if (!valid) {
      EXPECT_EQ(renderer.error(), valid.error().message()) << c.name;
    }
  }
}

}  // namespace
}  // namespace smx::sim
