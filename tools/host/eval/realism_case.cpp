#include "smx/eval/realism_case.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "smx/algo/lens.hpp"
#include "smx/sim/mesh_io.hpp"
#include "smx/sim/named_scenes.hpp"

namespace smx::eval {

namespace {

using sim::Mat3;
using sim::Vec3;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kMinBaselineM = 0.08;
constexpr double kMaxBaselineM = 0.25;
constexpr double kMinStripeCamPx = 3.0;
constexpr double kMaxStripeCamPx = 8.0;
constexpr int kStripes = 198;

// SplitMix64: the same numbers from every standard library, unlike <random>'s distributions.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31U);
  }
  double uniform() { return static_cast<double>(next() >> 11U) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + ((hi - lo) * uniform()); }
  int below(int n) { return static_cast<int>(uniform() * n); }
  bool chance(double p) { return uniform() < p; }
  double gauss() {  // Box–Muller
    const double u = 1.0 - uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * kPi * uniform());
  }
  // Index into weights (not necessarily normalised).
  template <std::size_t N>
  int pick(const std::array<double, N>& weights) {
    double total = 0;
    for (const double w : weights) {
      total += w;
    }
    double u = uniform() * total;
    for (std::size_t i = 0; i < N; ++i) {
      if (u < weights[i]) {
        return static_cast<int>(i);
      }
      u -= weights[i];
    }
    return static_cast<int>(N) - 1;
  }

 private:
  std::uint64_t state_;
};

std::uint64_t caseSeed(std::uint64_t seed, int index) {
  Rng mix(seed ^ (0xD1B54A32D192ED03ULL * (static_cast<std::uint64_t>(index) + 1)));
  return mix.next();
}

Mat3 rotX(double rad) {
  return Eigen::AngleAxisd(rad, Vec3::UnitX()).toRotationMatrix();
}
Mat3 rotY(double rad) {
  return Eigen::AngleAxisd(rad, Vec3::UnitY()).toRotationMatrix();
}
Mat3 rotZ(double rad) {
  return Eigen::AngleAxisd(rad, Vec3::UnitZ()).toRotationMatrix();
}
Mat3 randomRotation(Rng& rng) {
  Eigen::Quaterniond q(rng.gauss(), rng.gauss(), rng.gauss(), rng.gauss());
  q.normalize();
  return q.toRotationMatrix();
}

// Rows of R (world → device) for a device at `centre` looking at `target`, x level (horizontal),
// then rolled by `rollRad` about its axis and pitched by `pitchRad` about its x axis (so that the
// target appears at normalised y = tan(pitchRad)).
std::array<double, 9> aimedRotation(const Vec3& centre, const Vec3& target, double rollRad,
                                    double pitchRad) {
  const Vec3 z = (target - centre).normalized();
  const Vec3 x = Vec3::UnitY().cross(z).normalized();
  const Vec3 y = z.cross(x);
  Mat3 look;
  look.row(0) = x;
  look.row(1) = y;
  look.row(2) = z;
  Mat3 pitch;
  pitch << 1, 0, 0, 0, std::cos(pitchRad), std::sin(pitchRad), 0, -std::sin(pitchRad),
      std::cos(pitchRad);
  const Mat3 r = pitch * rotZ(-rollRad) * look;
  std::array<double, 9> out{};
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      out[(3 * i) + j] = r(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
    }
  }
  return out;
}

void place(algo::DeviceModel& d, const Vec3& centre, const std::array<double, 9>& r) {
  d.R = r;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::size_t row = 3 * i;
    d.t[i] = -((r[row] * centre.x()) + (r[row + 1] * centre.y()) + (r[row + 2] * centre.z()));
  }
}

Vec3 centreOf(const algo::DeviceModel& d) {
  const auto c = algo::lens::centre(d);
  return {c[0], c[1], c[2]};
}

algo::Camera drawCamera(Rng& rng, const RealismOptions& o, const std::string& id) {
  algo::Camera c;
  c.id = id;
  c.width = static_cast<int>(std::lround(640 * o.cameraScale));
  c.height = static_cast<int>(std::lround(480 * o.cameraScale));
  const double f = (c.width / 2.0) / std::tan(rng.uniform(45, 65) * kDeg / 2.0);
  const double cx = ((c.width - 1) / 2.0) + (rng.uniform(-0.02, 0.02) * c.width);
  const double cy = ((c.height - 1) / 2.0) + (rng.uniform(-0.02, 0.02) * c.height);
  c.K = {f, 0, cx, 0, f, cy, 0, 0, 1};
  c.dist = {rng.uniform(-0.15, 0.05), rng.uniform(-0.05, 0.10), rng.uniform(-0.001, 0.001),
            rng.uniform(-0.001, 0.001), 0.0};
  return c;
}

// Intrinsics only; the caller places it.
algo::Projector drawProjector(Rng& rng, const RealismOptions& o, const std::string& id) {
  algo::Projector p;
  p.id = id;
  const bool wxga = rng.chance(0.5);
  p.width = wxga ? 1280 : 1024;
  p.height = wxga ? 800 : 768;
  const double f = rng.uniform(1.1, 2.0) * p.width;
  // Lens shift: the optical axis above the image (principal point below its centre), as a
  // table-top projector throws upwards.
  const double cx = ((p.width - 1) / 2.0) + (rng.uniform(-0.02, 0.02) * p.width);
  const double cy = ((p.height - 1) / 2.0) + (rng.uniform(0.10, 0.40) * p.height);
  p.K = {f, 0, cx, 0, f, cy, 0, 0, 1};
  const std::array<double, 5> dist = {rng.uniform(-0.06, 0.06), rng.uniform(-0.02, 0.02),
                                      rng.uniform(-0.0005, 0.0005), rng.uniform(-0.0005, 0.0005),
                                      0.0};
  if (o.projectorDistortion) {
    p.dist = dist;
  }
  return p;
}

// Jacobian of cam0 pixel → projector pixel through the plane z = D at cam0's principal point.
std::optional<Eigen::Matrix2d> cameraToProjector(const algo::Camera& cam,
                                                 const algo::Projector& proj, double depthM) {
  auto at = [&](double x, double y) -> std::optional<Eigen::Vector2d> {
    const auto p = algo::lens::devicePoint(cam, {x, y}, depthM);  // cam0's frame is the world
    if (!p) {
      return std::nullopt;
    }
    const auto uv = algo::lens::project(proj, *p);
    if (!uv) {
      return std::nullopt;
    }
    return Eigen::Vector2d(uv->x, uv->y);
  };
  constexpr double kStep = 0.5;
  const auto x0 = at(cam.cx() - kStep, cam.cy());
  const auto x1 = at(cam.cx() + kStep, cam.cy());
  const auto y0 = at(cam.cx(), cam.cy() - kStep);
  const auto y1 = at(cam.cx(), cam.cy() + kStep);
  if (!x0 || !x1 || !y0 || !y1) {
    return std::nullopt;
  }
  Eigen::Matrix2d j;
  j.col(0) = (*x1 - *x0) / (2 * kStep);
  j.col(1) = (*y1 - *y0) / (2 * kStep);
  return j;
}

struct Placed {
  double axisDeg = 0;
  double stripeWidthPx = 0;
};

// Places projector p (intrinsics drawn) near the cameras along φ, aims it at T and sets its
// pattern so that cam0 sees its stripe gradient along φ, w px wide. nullopt: no placement with
// every baseline in range or with stripes that span the projector image; redraw.
std::optional<Placed> placeProjector(Rng& rng, algo::Projector& p, const algo::Rig& rig,
                                     const Vec3& hub, const Vec3& target, double phiDeg) {
  const double side = rng.chance(0.5) ? 0.0 : 180.0;
  const double dir = (phiDeg + side + rng.uniform(-15, 15)) * kDeg;
  const double b = rng.uniform(0.09, 0.24);
  const Vec3 centre =
      hub + Vec3(b * std::cos(dir), b * std::sin(dir), 0) - Vec3(0, 0, rng.uniform(0, 0.10));
  for (const auto& c : rig.cameras) {
    const double d = (centre - centreOf(c)).norm();
    if (d < kMinBaselineM || d > kMaxBaselineM) {
      return std::nullopt;
    }
  }
  const double pitch = std::atan(((p.height - 1) / 2.0 - p.cy()) / p.fy());
  place(p, centre, aimedRotation(centre, target, rng.uniform(-4, 4) * kDeg, pitch));
  const auto j = cameraToProjector(rig.cameras[0], p, target.z());
  if (!j || std::abs(j->determinant()) < 1e-9) {
    return std::nullopt;
  }
  // s = â·uv / stripePx, so ∇s in the camera is Jᵀâ / stripePx: â ∥ J⁻ᵀ g puts it along g.
  const Eigen::Vector2d g(std::cos(phiDeg * kDeg), std::sin(phiDeg * kDeg));
  const Eigen::Vector2d a = (j->transpose().inverse() * g).normalized();
  const double gain = (j->transpose() * a).norm();  // projector px per camera px along g
  const double angle = std::atan2(a.y(), a.x());
  const double extentPx =
      std::abs(p.width * std::cos(angle)) + std::abs(p.height * std::sin(angle));
  const double minWidth = std::max(kMinStripeCamPx, extentPx / (kStripes * gain));
  if (minWidth > kMaxStripeCamPx) {
    return std::nullopt;
  }
  const double w = rng.uniform(minWidth, kMaxStripeCamPx);
  p.pattern = {angle / kDeg, w * gain, 0.0};
  return Placed{phiDeg, w};
}

struct Aim {
  Vec3 hub;  // where the projectors gather: the cameras' mean centre
  Vec3 target;
  double phiDeg = 0;
};

// Draws projector p until a placement fits the envelope.
std::pair<algo::Projector, Placed> drawPlacedProjector(Rng& rng, const RealismOptions& o,
                                                       const algo::Rig& rig, const Aim& aim,
                                                       int p) {
  constexpr int kAttempts = 1000;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    algo::Projector proj = drawProjector(rng, o, "proj" + std::to_string(p));
    if (const auto placed = placeProjector(rng, proj, rig, aim.hub, aim.target, aim.phiDeg)) {
      return {proj, *placed};
    }
  }
  throw std::runtime_error("realism: no placement of projector " + std::to_string(p) +
                           " fits the envelope");
}

Vec3 randomColour(Rng& rng, double saturation, double value) {
  // Hue on the RGB hexagon; saturation mixes towards grey of the same value.
  const double h = rng.uniform(0, 6);
  const double x = 1.0 - std::abs(std::fmod(h, 2.0) - 1.0);
  Vec3 pure;
  switch (static_cast<int>(h)) {
    case 0:
      pure = {1, x, 0};
      break;
    case 1:
      pure = {x, 1, 0};
      break;
    case 2:
      pure = {0, 1, x};
      break;
    case 3:
      pure = {0, x, 1};
      break;
    case 4:
      pure = {x, 0, 1};
      break;
    default:
      pure = {1, 0, x};
      break;
  }
  return value * ((saturation * pure) + ((1.0 - saturation) * Vec3::Ones()));
}

// Grey, coloured or (with allowDark) dark. Walls and floors are never dark: a dark backdrop
// would outweigh the objects in every aggregate; dark objects test low albedo.
Vec3 plainAlbedo(Rng& rng, bool allowDark) {
  switch (rng.pick(std::array{0.5, 0.3, allowDark ? 0.2 : 0.0})) {
    case 0: {  // grey with a slight tint
      const double v = rng.uniform(0.4, 0.9);
      return Vec3(v, v, v) + Vec3(rng.uniform(-0.04, 0.04), rng.uniform(-0.04, 0.04), 0);
    }
    case 1:
      return randomColour(rng, rng.uniform(0.2, 0.6), rng.uniform(0.5, 0.9));
    default:  // dark
      return Vec3::Constant(rng.uniform(0.04, 0.15));
  }
}

struct AlbedoDraw {
  sim::Albedo albedo;
  const char* kind = "";
};

AlbedoDraw objectAlbedo(Rng& rng) {
  sim::Albedo a;
  switch (rng.pick(std::array{0.35, 0.2, 0.1, 0.2, 0.15})) {
    case 0: {
      const double v = rng.uniform(0.4, 0.9);
      a.rgb = Vec3(v, v, v) + Vec3(rng.uniform(-0.04, 0.04), rng.uniform(-0.04, 0.04), 0);
      return {a, "grey"};
    }
    case 1:
      a.rgb = randomColour(rng, rng.uniform(0.3, 0.7), rng.uniform(0.5, 0.9));
      return {a, "colour"};
    case 2:
      a.rgb = randomColour(rng, rng.uniform(0.85, 1.0), rng.uniform(0.7, 0.95));
      return {a, "saturated"};
    case 3:
      a.rgb = Vec3::Constant(rng.uniform(0.04, 0.15));
      return {a, "dark"};
    default: {
      sim::CheckerTexture t;
      t.squareM = rng.uniform(0.02, 0.06);
      t.colours.clear();
      const int n = 2 + rng.below(3);
      for (int i = 0; i < n; ++i) {
        t.colours.push_back(plainAlbedo(rng, true));
      }
      a.texture = t;
      return {a, "checker"};
    }
  }
}

struct Meshes {
  sim::Mesh bunny;
  sim::Mesh head;
};

Meshes loadMeshes() {
  auto dir = sim::sceneDir();
  if (!dir) {
    throw std::runtime_error(dir.error());
  }
  auto load = [&](const char* file) {
    auto m = sim::loadMesh(*dir / "meshes" / file);
    if (!m) {
      throw std::runtime_error(m.error().message());
    }
    return *std::move(m);
  };
  return {load("bun_zipper_res2.ply"), load("leeperrysmith_head.ply")};
}

// The bunny's bounding-box centre in its own coordinates (y up), metres.
Vec3 bunnyCentre() {
  return {-0.0168, 0.1100, -0.0016};
}

// One object centred at `at`, its size scaled by k; returns it and its extent below the centre
// (+y), metres.
std::pair<sim::Object, double> drawObject(Rng& rng, const Meshes& meshes, const Vec3& at,
                                          double k) {
  sim::Object o;
  o.pose.t = at;
  double below = 0;
  switch (rng.pick(std::array{0.2, 0.2, 0.15, 0.15, 0.15, 0.15})) {
    case 0: {
      o.name = "bunny";
      o.shape = meshes.bunny;
      o.pose.scale = k * rng.uniform(1.2, 2.4);
      // The mesh is y-up: turned upside down about z, then yawed and tipped.
      o.pose.R = rotY(rng.uniform(-70, 70) * kDeg) * rotX(rng.uniform(-15, 15) * kDeg) * rotZ(kPi);
      o.pose.t = at - (o.pose.R * (o.pose.scale * bunnyCentre()));
      below = 0.078 * o.pose.scale;
      break;
    }
    case 1:
      o.name = "head";
      o.shape = meshes.head;
      o.pose.scale = k * rng.uniform(0.025, 0.042);
      o.pose.R = rotY(rng.uniform(-50, 50) * kDeg) * rotX(rng.uniform(-15, 15) * kDeg) * rotX(kPi);
      below = 4.0 * o.pose.scale;
      break;
    case 2: {
      const double r = k * rng.uniform(0.04, 0.14);
      o.name = "sphere";
      o.shape = sim::Sphere{r};
      below = r;
      break;
    }
    case 3: {
      const Vec3 size =
          k * Vec3(rng.uniform(0.05, 0.25), rng.uniform(0.05, 0.25), rng.uniform(0.05, 0.25));
      o.name = "box";
      o.shape = sim::Box{size};
      o.pose.R = randomRotation(rng);
      below = size.norm() / 2;
      break;
    }
    case 4: {
      const sim::Cylinder c{k * rng.uniform(0.03, 0.10), k * rng.uniform(0.08, 0.30),
                            rng.chance(0.7)};
      o.name = "cylinder";
      o.shape = c;
      o.pose.R = rotZ(rng.uniform(-40, 40) * kDeg) * rotX(rng.uniform(-40, 40) * kDeg) *
                 rotY(rng.uniform(0, 360) * kDeg);
      below = std::hypot(c.radiusM, c.heightM / 2);
      break;
    }
    default: {
      const sim::Plane p{k * rng.uniform(0.12, 0.35), k * rng.uniform(0.12, 0.35)};
      o.name = "plane";
      o.shape = p;
      // Up to 70° off frontal about a random in-plane axis: steep tilts shrink the stripes.
      const double axis = rng.uniform(0, kPi);
      o.pose.R =
          Eigen::AngleAxisd(rng.uniform(0, 70) * kDeg, Vec3(std::cos(axis), std::sin(axis), 0))
              .toRotationMatrix() *
          rotZ(rng.uniform(0, kPi));
      below = std::hypot(p.widthM, p.heightM) / 2;
      break;
    }
  }
  auto albedo = objectAlbedo(rng);
  o.albedo = std::move(albedo.albedo);
  o.name += std::string(" (") + albedo.kind + ")";
  return {std::move(o), below};
}

void drawOptics(Rng& rng, sim::Scene& s, double distanceM) {
  const double ambient = rng.uniform(0, 0.12);
  s.lighting.ambient =
      ambient * Vec3(rng.uniform(0.8, 1.2), rng.uniform(0.8, 1.2), rng.uniform(0.8, 1.2));
  s.lighting.projectorPower = rng.uniform(0.3, 0.9);
  s.lighting.inverseSquare = rng.chance(0.7);
  s.lighting.referenceDistanceM = distanceM;
  s.lighting.projectorDefocusSigmaPx = rng.uniform(0, 1.2);
  s.camera.defocusSigmaPx = rng.uniform(0, 0.8);
  s.camera.gain = rng.uniform(0.8, 1.4);
  // Colour crosstalk: each camera channel sees up to 15 % of each other; rows sum to 1 so that
  // white stays white.
  Mat3 c = Mat3::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (i != j) {
        c(i, j) = rng.uniform(0, 0.15);
      }
    }
    c.row(i) /= c.row(i).sum();
  }
  s.camera.crosstalk = c;
}

// The simulator's realism fields (docs/simulator.md): finite projector contrast and display
// gamma, the camera's response curve, vignetting and colour mosaic, motion blur of slowly moving
// objects over the exposure, and gloss. Sets exactly these fields.
void drawRealOptics(Rng& rng, sim::Scene& s) {
  s.lighting.projectorBlackLevel = rng.uniform(0.001, 0.02);
  s.lighting.projectorGamma = rng.uniform(1.8, 2.4);
  s.camera.responseGamma = rng.uniform(1.0, 2.2);
  s.camera.vignetting = rng.uniform(0, 0.4);
  constexpr std::array<const char*, 5> kMosaics = {"none", "rggb", "bggr", "grbg", "gbrg"};
  s.camera.bayer = kMosaics[static_cast<std::size_t>(rng.below(5))];
  s.camera.exposure = rng.uniform(0, 0.5);
  s.camera.exposureSamples = 4;
  for (auto& o : s.objects) {
    if (o.name == "wall" || o.name == "floor") {
      continue;
    }
    // Handheld drift: up to 2 mm and 0.3° per frame, about 1 px of blur over the exposure.
    o.motion.velocityMPerFrame =
        Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)).normalized() *
        rng.uniform(0, 0.002);
    o.motion.axis = Vec3::UnitY();
    o.motion.pivot = o.pose.t;
    o.motion.angularDegPerFrame = rng.uniform(-0.3, 0.3);
    o.albedo.specular = rng.uniform(0, 0.3);
    o.albedo.shininess = rng.uniform(10, 200);
  }
}

std::string fixed2(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

}  // namespace

RealismCase generateRealismCase(std::uint64_t seed, int index, const RealismOptions& options) {
  Rng rng(caseSeed(seed, index));
  RealismCase out;
  out.index = index;
  auto& rig = out.rig;
  const double d = rng.uniform(0.5, 1.2);
  out.workingDistanceM = d;
  const Vec3 target(0, 0, d);

  const int cameras = rng.chance(0.35) ? 2 : 1;
  const int projectors = rng.chance(0.5) ? 3 : 2;
  rig.cameras.push_back(drawCamera(rng, options, "cam0"));
  place(rig.cameras[0], Vec3::Zero(), aimedRotation(Vec3::Zero(), target, 0, 0));
  Vec3 hub = Vec3::Zero();
  if (cameras == 2) {
    rig.cameras.push_back(drawCamera(rng, options, "cam1"));
    const double beta = rng.uniform(0, 2 * kPi);
    const Vec3 c1 = rng.uniform(0.08, 0.20) * Vec3(std::cos(beta), std::sin(beta), 0);
    place(rig.cameras[1], c1, aimedRotation(c1, target, 0, 0));
    hub = c1 / 2;
  }

  const double phi0 = rng.uniform(0, 180);
  std::vector<double> phis = {phi0};
  if (projectors == 2) {
    phis.push_back(phi0 + rng.uniform(60, 90));
  } else {
    phis.push_back(phi0 + 60);
    phis.push_back(phi0 + 120);
  }
  for (int p = 0; p < projectors; ++p) {
    const double phi = std::fmod(phis[static_cast<std::size_t>(p)], 180.0);
    auto [proj, placed] = drawPlacedProjector(rng, options, rig, {hub, target, phi}, p);
    rig.projectors.push_back(std::move(proj));
    out.axisDeg.push_back(placed.axisDeg);
    out.stripeWidthPx.push_back(placed.stripeWidthPx);
  }

  // Objects around T, then what stands behind and under them.
  const Meshes meshes = loadMeshes();
  auto& scene = out.scene;
  const int objects = 1 + rng.pick(std::array{0.4, 0.4, 0.2});
  double lowest = 0;
  std::string names;
  for (int i = 0; i < objects; ++i) {
    const Vec3 at(rng.uniform(-0.12, 0.12) * d, rng.uniform(-0.08, 0.08) * d,
                  d + rng.uniform(-0.08, 0.08));
    // Sizes follow the distance: a near scan frames smaller things.
    auto [object, below] = drawObject(rng, meshes, at, std::clamp(d / 0.9, 0.65, 1.2));
    lowest = std::max(lowest, at.y() + below);
    names += (i == 0 ? "" : ", ") + object.name;
    scene.objects.push_back(std::move(object));
  }
  const int background = rng.pick(std::array{0.4, 0.2, 0.4});  // wall, floor, both
  const double halfView =
      (rig.cameras[0].width / 2.0) / rig.cameras[0].fx();  // tan of half the view
  std::string behind;
  if (background != 1) {
    const double z = d + rng.uniform(0.15, 0.45);
    sim::Object wall;
    wall.name = "wall";
    const double width = (2.0 * z * halfView * 1.6) + 0.5;
    wall.shape = sim::Plane{width, width};
    wall.pose.t = Vec3(0, 0, z);
    wall.pose.R = rotY(rng.uniform(-25, 25) * kDeg) * rotX(rng.uniform(-10, 10) * kDeg);
    wall.albedo.rgb = plainAlbedo(rng, false);
    scene.objects.push_back(std::move(wall));
    behind = "wall";
  }
  if (background != 0) {
    sim::Object floor;
    floor.name = "floor";
    floor.shape = sim::Plane{1.5, 1.2};
    // Tipped 50–80° back from facing the camera: seen obliquely, as a table top is.
    floor.pose.R = rotX(-rng.uniform(50, 80) * kDeg);
    floor.pose.t = Vec3(0, lowest, d + 0.1);
    floor.albedo.rgb = plainAlbedo(rng, false);
    scene.objects.push_back(std::move(floor));
    behind += behind.empty() ? "floor" : " + floor";
  }
  drawOptics(rng, scene, d);
  drawRealOptics(rng, scene);

  out.summary = std::to_string(projectors) + "P" + std::to_string(cameras) + "C, " + fixed2(d) +
                " m; " + names + "; " + behind;
  return out;
}

}  // namespace smx::eval
