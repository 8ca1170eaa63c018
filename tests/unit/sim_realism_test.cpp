#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "closed_form_optics.hpp"
#include "smx/algo/lens.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/algo/stripe_code.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/sim/renderer.hpp"
#include "source_dir.hpp"

// The optics of real rigs in the renderer (docs/simulator.md, docs/scene-format.md): projector
// black level and gamma, gloss, motion blur, vignetting, the camera's response curve, the Bayer
// mosaic and projector lens distortion, each against what geometry and the documented laws
// predict, computed here independently of the renderer.
namespace smx::sim {
namespace {

using algo::Rgb8;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// rig_2proj_1cam with cam0 at 1/factor the resolution (same field of view, pixel centres at
// integers).
algo::Rig smallRig(int factor) {
  auto loaded = config::loadRig(smx::test::sourceDir() / "boards" / "sim" / "rig_2proj_1cam.json");
  if (!loaded) {
    ADD_FAILURE() << loaded.error().message();
    return {};
  }
  algo::Rig rig = *loaded;
  auto& c = rig.cameras[0];
  const double f = factor;
  c.K[0] /= f;
  c.K[4] /= f;
  c.K[2] = (c.K[2] - (f - 1.0) / 2.0) / f;
  c.K[5] = (c.K[5] - (f - 1.0) / 2.0) / f;
  c.width /= factor;
  c.height /= factor;
  return rig;
}

// Noise-free, ambient-free, one sample per pixel.
Scene quietScene() {
  Scene s;
  s.lighting.ambient = Vec3::Zero();
  s.camera.noiseSigma = Vec3::Zero();
  s.supersampling = 1;
  return s;
}

Object wall(double z, const Vec3& albedo) {
  Object o;
  o.shape = Plane{3.0, 3.0};
  o.pose.t = {0.0, 0.0, z};
  o.albedo.rgb = albedo;
  return o;
}

std::size_t at(int x, int y, int width) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
         static_cast<std::size_t>(x);
}

// A camera image with its depth and per-projector stripe truth.
struct Frame {
  Frame(const algo::DeviceModel& camera, std::size_t projectors)
      : width(camera.width), height(camera.height), image(count()), depth(count()) {
    truth.depth = *algo::ImageView<float>::packed(depth, width, height);
    stripe.resize(projectors, std::vector<float>(count()));
    for (std::size_t p = 0; p < projectors; ++p) {
      ProjectorTruthViews views;
      views.stripe = *algo::ImageView<float>::packed(stripe[p], width, height);
      truth.projectors.push_back(views);
    }
  }
  [[nodiscard]] std::size_t count() const {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  }
  [[nodiscard]] const Rgb8& px(int x, int y) const { return image[at(x, y, width)]; }

  int width;
  int height;
  std::vector<Rgb8> image;
  std::vector<float> depth;
  std::vector<std::vector<float>> stripe;
  GroundTruthViews truth;
};

Frame render(const algo::Rig& rig, const Scene& scene, std::vector<bool> lit, int frame = 0,
             std::uint64_t seed = 1) {
  Frame f(rig.cameras[0], rig.projectors.size());
  auto renderer = Renderer::create(rig, scene);
  if (!renderer) {
    ADD_FAILURE() << renderer.error();
    return f;
  }
  FrameRequest request;
  request.frame = frame;
  request.lit = std::move(lit);
  request.seed = seed;
  const auto ok =
      (*renderer)->render(request, *algo::RgbView::packed(f.image, f.width, f.height), &f.truth);
  EXPECT_TRUE(ok.has_value()) << (ok ? "" : ok.error());
  return f;
}

std::uint8_t channel(const Rgb8& p, std::size_t c) {
  return c == 0 ? p.r : (c == 1 ? p.g : p.b);
}

// ---- Independent geometry (docs/rig-format.md, docs/pattern.md) ----

struct Ray {
  Vec3 o;
  Vec3 d;
};

Ray cameraRay(const algo::DeviceModel& camera, double x, double y) {
  const auto r = algo::lens::pixelRay(camera, {x, y});
  EXPECT_TRUE(r.has_value());
  return {{r->origin[0], r->origin[1], r->origin[2]},
          {r->direction[0], r->direction[1], r->direction[2]}};
}

// The first point of the fronto-parallel wall z = const on the ray.
Vec3 onWall(const Ray& r, double z) {
  return r.o + (z - r.o.z()) / r.d.z() * r.d;
}

using test::centreOf;
using test::projectPoint;
using test::stripeFormula;

// The projector pixel nearest (u, v), or nullopt outside the image or within 1e-4 px of the
// line between two pixels (either may light the point).
std::optional<std::array<int, 2>> projectorPixel(const algo::Projector& p,
                                                 const std::array<double, 2>& uv) {
  const auto clear = [](double c) {
    const double f = c + 0.5 - std::floor(c + 0.5);
    return f > 1e-4 && f < 1.0 - 1e-4;
  };
  if (!(uv[0] > -0.5 && uv[0] < p.width - 0.5 && uv[1] > -0.5 && uv[1] < p.height - 0.5) ||
      !clear(uv[0]) || !clear(uv[1])) {
    return std::nullopt;
  }
  return std::array<int, 2>{static_cast<int>(std::floor(uv[0] + 0.5)),
                            static_cast<int>(std::floor(uv[1] + 0.5))};
}

// The pattern colour (docs/pattern.md: the stripe at the pixel centre, a full primary; black
// beyond the sequence) as channel levels 0 or 1.
Vec3 patternLevels(const algo::Projector& p, const std::array<int, 2>& pixel) {
  const double s = stripeFormula(p, pixel[0], pixel[1]);
  Vec3 level = Vec3::Zero();
  if (s >= 0.0 && s < algo::stripe::kStripes) {
    level[algo::stripe::indexOf(algo::stripe::kSequence[static_cast<std::size_t>(s)])] = 1.0;
  }
  return level;
}

// ---- Projector: black level and gamma ----

// Given a projector of contrast 10:1 (black level 0.1) and gamma 2.2 on a white wall, when its
// stripes are rendered, then each channel a stripe leaves black carries 0.1 of a full pixel's
// light and each lit channel the full light (a full level is 1 whatever the gamma), as
// irradiance = power · cos θ · (black + (1 − black) · level^γ) predicts.
TEST(RenderRealism, ProjectorBlackLevelLightsTheBlackChannels) {
  const algo::Rig rig = smallRig(4);
  Scene scene = quietScene();
  scene.lighting.projectorPower = 0.8;
  scene.lighting.projectorBlackLevel = 0.1;
  scene.lighting.projectorGamma = 2.2;
  scene.objects.push_back(wall(1.0, {0.9, 0.9, 0.9}));
  const Frame f = render(rig, scene, {true, false});

  const auto& proj = rig.projectors[0];
  const Vec3 c = centreOf(proj);
  int dark = 0;
  int unlit = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const Vec3 p = onWall(cameraRay(rig.cameras[0], x, y), 1.0);
      const auto uv = projectPoint(proj, p);
      Vec3 expected = Vec3::Zero();
      if (uv && (*uv)[0] > -0.4 && (*uv)[0] < proj.width - 0.6 && (*uv)[1] > -0.4 &&
          (*uv)[1] < proj.height - 0.6) {
        const auto pixel = projectorPixel(proj, *uv);
        if (!pixel) {
          continue;
        }
        const Vec3 level = patternLevels(proj, *pixel);
        const double cosTheta = Vec3(0, 0, -1).dot((c - p).normalized());
        for (int k = 0; k < 3; ++k) {
          const double emitted = 0.1 + 0.9 * std::pow(level[k], 2.2);
          expected[k] = 255.0 * 0.9 * 0.8 * cosTheta * emitted;
          dark += level[k] == 0.0 ? 1 : 0;
        }
      } else if (!uv || (*uv)[0] < -0.6 || (*uv)[0] > proj.width - 0.4 || (*uv)[1] < -0.6 ||
                 (*uv)[1] > proj.height - 0.4) {
        ++unlit;  // beyond the projector's image there is no light at all
      } else {
        continue;
      }
      for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_NEAR(channel(f.px(x, y), k), expected[static_cast<Eigen::Index>(k)], 0.5 + 1e-3)
            << x << "," << y << " channel " << k;
      }
    }
  }
  EXPECT_GT(dark, 10000);
  EXPECT_GT(unlit, 100);
}

// Given a defocused projector, when its display gamma changes, then the image does not: the
// pattern's levels are 0 or 1, which any gamma keeps, and the lens blurs the emitted light after
// the display (a gamma applied to the blurred light would bend the stripe edges).
TEST(RenderRealism, ProjectorGammaActsOnLevelsBeforeTheLensBlur) {
  const algo::Rig rig = smallRig(4);
  Scene scene = quietScene();
  scene.lighting.projectorDefocusSigmaPx = 3.0;
  scene.objects.push_back(wall(1.0, {0.9, 0.9, 0.9}));
  const Frame linear = render(rig, scene, {true, true});
  scene.lighting.projectorGamma = 2.5;
  const Frame curved = render(rig, scene, {true, true});
  EXPECT_EQ(linear.image, curved.image);
}

// ---- Camera: response curve and vignetting ----

// Given an evenly lit grey wall of linear level 51 before the gain of 2, when the camera's
// response gamma is 2.2, then every pixel is 255 · (102/255)^(1/2.2): the curve comes after the
// gain.
TEST(RenderRealism, ResponseGammaMapsMidGreyToTheDocumentedLevel) {
  const algo::Rig rig = smallRig(4);
  Scene scene = quietScene();
  scene.lighting.ambient = {0.4, 0.4, 0.4};
  scene.camera.gain = 2.0;
  scene.camera.responseGamma = 2.2;
  scene.objects.push_back(wall(1.0, {0.5, 0.5, 0.5}));
  const Frame f = render(rig, scene, {false, false});
  const double expected = 255.0 * std::pow(102.0 / 255.0, 1.0 / 2.2);  // 167.7
  for (const Rgb8& px : f.image) {
    ASSERT_NEAR(px.r, expected, 0.5 + 1e-3);
    ASSERT_NEAR(px.g, expected, 0.5 + 1e-3);
    ASSERT_NEAR(px.b, expected, 0.5 + 1e-3);
  }
}

// Given an evenly lit wall facing the camera, when vignetting is 0.5, then each pixel keeps
// 1 − 0.5 · (r / r_corner)² of its light, r from the principal point: the corner pixel about half
// of the centre's.
TEST(RenderRealism, VignettingFollowsItsQuadraticLawToTheCorner) {
  const algo::Rig rig = smallRig(4);
  Scene scene = quietScene();
  scene.lighting.ambient = {1.0, 1.0, 1.0};
  scene.camera.vignetting = 0.5;
  scene.objects.push_back(wall(1.0, {0.8, 0.8, 0.8}));
  const Frame f = render(rig, scene, {false, false});

  const auto& camera = rig.cameras[0];
  const double cx = camera.K[2];
  const double cy = camera.K[5];
  // The principal point is the image centre here, so all four corners are as far.
  const double corner2 = (cx + 0.5) * (cx + 0.5) + (cy + 0.5) * (cy + 0.5);
  const auto expected = [&](int x, int y) {
    const double r2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
    return 204.0 * (1.0 - 0.5 * r2 / corner2);
  };
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      ASSERT_NEAR(f.px(x, y).g, expected(x, y), 0.5 + 1e-3) << x << "," << y;
    }
  }
  const double ratio =
      static_cast<double>(f.px(0, 0).g) / f.px(f.width / 2, f.height / 2).g;  // 0.507
  EXPECT_NEAR(ratio, 0.5, 0.02);
}

// ---- Camera: Bayer mosaic ----

// The channel the filter keeps at (x, y): pattern letters row by row from the top left.
std::size_t keptChannel(std::string_view pattern, int x, int y) {
  const char letter = pattern[static_cast<std::size_t>((y % 2) * 2 + (x % 2))];
  return letter == 'r' ? 0 : (letter == 'g' ? 1 : 2);
}

// Given a pure red wall in white light and no noise, when the camera has a Bayer mosaic, then the
// demosaiced image is full red, no green, no blue, up to the image border.
TEST(RenderRealism, BayerDemosaicKeepsAPureRedSurfaceRed) {
  const algo::Rig rig = smallRig(4);
  Scene scene = quietScene();
  scene.lighting.ambient = {1.0, 1.0, 1.0};
  scene.objects.push_back(wall(1.0, {1.0, 0.0, 0.0}));
  for (const std::string pattern : {"rggb", "bggr", "grbg", "gbrg"}) {
    scene.camera.bayer = pattern;
    const Frame f = render(rig, scene, {false, false});
    for (const Rgb8& px : f.image) {
      ASSERT_EQ(px, (Rgb8{255, 0, 0})) << pattern;
    }
  }
}

// Given a busy noisy frame (stripes of two projectors, noise on), when rendered with each
// mosaic, then every pixel keeps the plain render's value of its filter's channel, and each other
// channel is the mean, rounded half up, of the plain render's values at the 3 × 3 neighbours whose
// filter kept that channel (bilinear demosaic).
TEST(RenderRealism, BayerMosaicKeepsThePlainValuesAndInterpolatesTheRest) {
  const algo::Rig rig = smallRig(4);
  Scene scene;
  scene.objects.push_back(wall(1.0, {0.9, 0.8, 0.7}));
  const Frame plain = render(rig, scene, {true, true}, 0, 5);
  for (const std::string pattern : {"rggb", "bggr", "grbg", "gbrg"}) {
    scene.camera.bayer = pattern;
    const Frame f = render(rig, scene, {true, true}, 0, 5);
    for (int y = 0; y < f.height; ++y) {
      for (int x = 0; x < f.width; ++x) {
        const std::size_t own = keptChannel(pattern, x, y);
        ASSERT_EQ(channel(f.px(x, y), own), channel(plain.px(x, y), own))
            << pattern << " " << x << "," << y;
        for (std::size_t c = 0; c < 3; ++c) {
          if (c == own) {
            continue;
          }
          unsigned sum = 0;
          unsigned n = 0;
          for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, f.height - 1); ++ny) {
            for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, f.width - 1); ++nx) {
              if (keptChannel(pattern, nx, ny) == c) {
                sum += channel(plain.px(nx, ny), c);
                ++n;
              }
            }
          }
          ASSERT_EQ(channel(f.px(x, y), c), (sum + n / 2) / n)
              << pattern << " " << x << "," << y << " channel " << c;
        }
      }
    }
  }
}

// ---- Motion blur ----

// A 0.3 m square at z = 1 m moving along x at 0.025 m per frame, lit only by ambient light, seen
// by a camera without distortion (fx = 200 px/m at 1 m).
Scene movingSquare(double exposure, int samples) {
  Scene scene = quietScene();
  scene.supersampling = 4;
  scene.lighting.ambient = {1.0, 1.0, 1.0};
  Object square;
  square.shape = Plane{0.3, 0.3};
  square.pose.t = {0.0, 0.0, 1.0};
  square.albedo.rgb = {0.8, 0.8, 0.8};
  square.motion.velocityMPerFrame = {0.025, 0.0, 0.0};
  scene.objects.push_back(square);
  scene.camera.exposure = exposure;
  scene.camera.exposureSamples = samples;
  return scene;
}

// The fraction of pixel x (a box [x − ½, x + ½]) that an edge moving from `from` to `to` (pixel
// coordinates) over the exposure leaves covered on its left, averaged over the exposure: the
// blur's closed form, integrated finely here.
double coveredLeftOfMovingEdge(double x, double from, double to) {
  constexpr int kSteps = 400;
  double covered = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const double edge = from + (to - from) * (i + 0.5) / kSteps;
    covered += std::clamp(edge - (x - 0.5), 0.0, 1.0);
  }
  return covered / kSteps;
}

// Given the moving square at frame 2 with an exposure of 0.8 frame, when rendered, then its
// right edge is smeared over velocity · exposure / pixel footprint = 0.025 · 0.8 / 0.005 = 4 px
// centred on the edge's position at the frame instant, as the closed form says; and the depth
// truth is the frame instant's.
TEST(RenderRealism, MotionBlurSpreadsAMovingEdgeOverVelocityTimesExposure) {
  algo::Rig rig = smallRig(4);
  rig.cameras[0].dist = {};
  const auto& camera = rig.cameras[0];
  const int frame = 2;
  const Frame sharp = render(rig, movingSquare(0.0, 1), {false, false}, frame);
  const Frame blurred = render(rig, movingSquare(0.8, 16), {false, false}, frame);

  // The right edge at the frame instant: x = 0.15 + 2 · 0.025 = 0.2 m.
  const double edge = camera.K[0] * 0.2 / 1.0 + camera.K[2];  // 119.5
  const double spread = camera.K[0] * 0.025 * 0.8 / 1.0;      // 4 px
  const int y = static_cast<int>(camera.K[5] + 0.5);          // the row through the square's middle
  for (int x = static_cast<int>(edge) - 5; x <= static_cast<int>(edge) + 5; ++x) {
    const double expected =
        204.0 * coveredLeftOfMovingEdge(x, edge - spread / 2, edge + spread / 2);
    // 16 time × 4 × 4 samples against the continuous integral: off by 1.5 grey levels at most.
    EXPECT_NEAR(blurred.px(x, y).g, expected, 4.0) << "x " << x;
  }
  // Without exposure the edge is sharp: one pixel between the square and the background.
  for (int x = static_cast<int>(edge) - 5; x <= static_cast<int>(edge) + 5; ++x) {
    const double expected = 204.0 * coveredLeftOfMovingEdge(x, edge, edge);
    EXPECT_NEAR(sharp.px(x, y).g, expected, 0.5 + 1e-3) << "x " << x;
  }
  EXPECT_EQ(blurred.depth.size(), sharp.depth.size());
  for (std::size_t i = 0; i < sharp.depth.size(); ++i) {
    ASSERT_TRUE(blurred.depth[i] == sharp.depth[i] ||
                (std::isnan(blurred.depth[i]) && std::isnan(sharp.depth[i])))
        << i;
  }
}

// Given no exposure, when time samples are asked for, then they are ignored: the image is the
// frame instant's, byte for byte.
TEST(RenderRealism, ZeroExposureIgnoresTheTimeSamples) {
  algo::Rig rig = smallRig(4);
  const Frame one = render(rig, movingSquare(0.0, 1), {true, true}, 3, 9);
  const Frame many = render(rig, movingSquare(0.0, 16), {true, true}, 3, 9);
  EXPECT_EQ(one.image, many.image);
}

// ---- Gloss ----

// Given a black glossy sphere lit by one projector, when rendered, then its brightest pixel is
// where the sphere's normal bisects the directions to the camera and to the projector (the
// mirror point, found here by fixed-point iteration), within 2 px, and is as bright as the
// projector's light there.
TEST(RenderRealism, SpecularHighlightSitsAtTheMirrorPoint) {
  const algo::Rig rig = smallRig(2);
  Scene scene = quietScene();
  Object ball;
  const Vec3 centre(0.0, 0.03, 0.8);  // off the projector's middle row
  const double radius = 0.1;
  ball.shape = Sphere{radius};
  ball.pose.t = centre;
  ball.albedo.rgb = Vec3::Zero();
  ball.albedo.specular = 1.0;
  ball.albedo.shininess = 200.0;
  scene.objects.push_back(ball);
  const Frame f = render(rig, scene, {true, false});

  const Vec3 eye = centreOf(rig.cameras[0]);
  const Vec3 light = centreOf(rig.projectors[0]);
  Vec3 n = ((eye - centre).normalized() + (light - centre).normalized()).normalized();
  for (int i = 0; i < 100; ++i) {
    const Vec3 x = centre + radius * n;
    n = ((eye - x).normalized() + (light - x).normalized()).normalized();
  }
  const Vec3 mirror = centre + radius * n;
  const auto predicted = projectPoint(rig.cameras[0], mirror);
  ASSERT_TRUE(predicted.has_value());
  const auto lightPixel = projectPoint(rig.projectors[0], mirror);
  ASSERT_TRUE(lightPixel && projectorPixel(rig.projectors[0], *lightPixel));

  int bestX = -1;
  int bestY = -1;
  int best = -1;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const Rgb8 p = f.px(x, y);
      const int level = std::max({p.r, p.g, p.b});
      if (level > best) {
        best = level;
        bestX = x;
        bestY = y;
      }
    }
  }
  EXPECT_LE(std::hypot(bestX - (*predicted)[0], bestY - (*predicted)[1]), 2.0)
      << "brightest " << bestX << "," << bestY << "; predicted " << (*predicted)[0] << ","
      << (*predicted)[1];
  const double cosTheta = n.dot((light - mirror).normalized());
  EXPECT_NEAR(best, 255.0 * 0.9 * cosTheta, 0.05 * 255.0 * 0.9 * cosTheta);
}

// ---- Projector lens distortion ----

// Given a projector with strong barrel distortion lighting a wall, when rendered, then the truth
// stripe is algo::stripeCoordinate of lens::project of the truth point, and every camera pixel
// shows the colour of the projector pixel that the distortion formula (computed here) sends it
// to: the straight stripe boundaries of the slide are bent on the wall as the distortion says.
TEST(RenderRealism, ProjectorDistortionBendsTheStripesAsItsModelSays) {
  algo::Rig rig = smallRig(4);
  auto& proj = rig.projectors[0];
  proj.dist = {-0.3, 0.1, 0.002, -0.001, 0.0};
  Scene scene = quietScene();
  scene.objects.push_back(wall(0.9, {1.0, 1.0, 1.0}));
  const Frame f = render(rig, scene, {true, false});

  const auto& camera = rig.cameras[0];
  int checked = 0;
  int bent = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const Ray r = cameraRay(camera, x, y);
      const double depth = f.depth[at(x, y, f.width)];
      const double s = f.stripe[0][at(x, y, f.width)];
      if (!std::isnan(s)) {
        const Vec3 p = r.o + depth / r.d.z() * r.d;  // cam0 is the world frame
        const auto uv = algo::lens::project(proj, {p.x(), p.y(), p.z()});
        ASSERT_TRUE(uv.has_value());
        EXPECT_NEAR(s, algo::stripeCoordinate(proj.pattern, proj.width, proj.height, uv->x, uv->y),
                    1e-3);
      }
      const Vec3 p = onWall(r, 0.9);
      const auto uv = projectPoint(proj, p);
      const auto pixel = uv ? projectorPixel(proj, *uv) : std::nullopt;
      if (!pixel) {
        continue;
      }
      const Vec3 level = patternLevels(proj, *pixel);
      const Rgb8 px = f.px(x, y);
      const std::array<int, 3> rgb = {px.r, px.g, px.b};
      const auto shown = std::max_element(rgb.begin(), rgb.end()) - rgb.begin();
      Eigen::Index expected = 0;
      level.maxCoeff(&expected);
      ASSERT_EQ(shown, expected) << x << "," << y;
      EXPECT_GT(rgb[static_cast<std::size_t>(shown)], 100);
      ++checked;
      const auto straight = projectPoint(proj, p, false);
      const auto straightPixel = straight ? projectorPixel(proj, *straight) : std::nullopt;
      const auto stripeOf = [&](const std::array<int, 2>& q) {
        return std::floor(stripeFormula(proj, q[0], q[1]));
      };
      bent += !straightPixel || stripeOf(*straightPixel) != stripeOf(*pixel) ? 1 : 0;
    }
  }
  EXPECT_GT(checked, 5000);
  // The distortion moves much of the wall to other stripes: the check above can tell.
  EXPECT_GT(bent, checked / 4);
}

// ---- Determinism ----

// Given every realism setting at once on a moving glossy object, when the same request is
// rendered twice (rows shared between threads anew each time), then the images are equal bit
// for bit, and another seed changes the noise.
TEST(RenderRealism, AllSettingsTogetherAreDeterministicForASeed) {
  const algo::Rig rig = smallRig(4);
  Scene scene = movingSquare(0.6, 5);
  scene.camera.noiseSigma = {1.8, 1.3, 1.7};
  scene.lighting.projectorBlackLevel = 0.01;
  scene.lighting.projectorGamma = 2.2;
  scene.lighting.projectorDefocusSigmaPx = 1.0;
  scene.camera.vignetting = 0.4;
  scene.camera.responseGamma = 2.2;
  scene.camera.defocusSigmaPx = 0.7;
  scene.camera.bayer = "bggr";
  scene.objects[0].albedo.specular = 0.5;
  scene.objects[0].albedo.shininess = 300.0;
  const Frame a = render(rig, scene, {true, true}, 4, 21);
  const Frame b = render(rig, scene, {true, true}, 4, 21);
  const Frame c = render(rig, scene, {true, true}, 4, 22);
  EXPECT_EQ(a.image, b.image);
  EXPECT_NE(a.image, c.image);
}

}  // namespace
}  // namespace smx::sim
