#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "smx/sim/handheld.hpp"

// What the simulated rig looks at: objects with shape, pose, motion and albedo, plus the light and
// camera-response settings of the render (scene.json, docs/scene-format.md). World frame and
// units as in rig.json: metres, x right, y down, z forward (the example rigs use cam0's frame).
namespace smx::sim {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Object → world: X = R · (scale · x) + t.
struct Pose {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  double scale = 1.0;
};

// Rigid motion standing in for a moving object: at frame f the object is first rotated by
// f · angularDegPerFrame about `axis` (world direction) through `pivot` (world point), then
// translated by f · velocityMPerFrame. Frame 0 is the pose as given.
struct Motion {
  Vec3 velocityMPerFrame = Vec3::Zero();
  Vec3 axis = Vec3::UnitY();
  double angularDegPerFrame = 0.0;
  Vec3 pivot = Vec3::Zero();
};

// The scene's turntable: objects standing on it turn with it by the board's turntable angle,
// right-handed about `axis` (world direction, unit) through `pivot` (world point).
struct TurntableMount {
  Vec3 axis = -Vec3::UnitY();  // up in a level rig (y is down)
  Vec3 pivot = Vec3::Zero();
};

// A target placed by hand: the object holds each pose for holdFrames frames, then jumps to the
// next, and starts again after the last (frame f shows poses[(f / holdFrames) mod n]). Empty
// poses: the object keeps `Object::pose`. An object with a sequence has no Motion.
struct PoseSequence {
  int holdFrames = 1;
  std::vector<Pose> poses;
};

// Albedo textures are evaluated at the object-local surface point (x, y) (a planar mapping along
// local z; for a plane that is its own surface).
struct CheckerTexture {
  double squareM = 0.04;
  // Cycled along x, shifted by one per row: the paper's Fig. 13 RGBCMY panel by default.
  std::vector<Vec3> colours = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 1, 1}, {1, 0, 1}, {1, 1, 0}};
};

struct ImageTexture {
  std::string path;     // PNG, resolved relative to the scene file
  double widthM = 0.2;  // the image spans [-w/2, w/2] × [-h/2, h/2] in local x, y; repeats
  double heightM = 0.2;
  int width = 0;  // filled by the loader
  int height = 0;
  std::vector<std::array<float, 3>> texels;  // linear albedo in [0, 1], row-major
};

struct Albedo {
  Vec3 rgb{0.8, 0.8, 0.8};  // constant albedo in [0, 1] per channel (used when no texture)
  std::variant<std::monostate, CheckerTexture, ImageTexture> texture;
  // Blinn–Phong gloss of projector light: specular · (n·h)^shininess · irradiance, h the half
  // vector between the directions to the projector and to the camera. albedo + specular may
  // exceed 1 only as glossy highlights do.
  double specular = 0.0;    // [0, 1]
  double shininess = 50.0;  // [1, 10000]
};

// Shapes, in object-local coordinates, centred on the local origin.
struct Plane {  // finite rectangle in the local x-y plane, normal ±z (two-sided)
  double widthM = 1.0;
  double heightM = 1.0;
};
struct Box {
  Vec3 sizeM{0.1, 0.1, 0.1};
};
struct Sphere {
  double radiusM = 0.1;
};
struct Cylinder {  // axis along local y (down in a level rig), from -h/2 to +h/2
  double radiusM = 0.05;
  double heightM = 0.1;
  bool capped = true;
};
struct Mesh {
  std::string path;                       // PLY or OBJ, resolved relative to the scene file
  std::vector<Eigen::Vector3f> vertices;  // filled by the loader
  std::vector<std::array<std::uint32_t, 3>> triangles;  // filled by the loader
};

using Shape = std::variant<Plane, Box, Sphere, Cylinder, Mesh>;

struct Object {
  std::string name;
  Shape shape;
  Pose pose;
  Motion motion;
  PoseSequence poseSequence;
  Albedo albedo;
  // Turned with the scene's turntable, after its pose and motion (the scene must have one).
  bool onTurntable = false;
};

struct Lighting {
  // Light that does not come from the projectors, as a fraction of full scale per channel.
  Vec3 ambient{0.03, 0.03, 0.03};
  // Projector brightness: irradiance of a full-level pixel on a surface facing it at
  // referenceDistanceM, as a fraction of full scale.
  double projectorPower = 0.9;
  bool inverseSquare = false;  // 1/d² falloff relative to referenceDistanceM
  double referenceDistanceM = 0.9;
  double projectorDefocusSigmaPx = 0.0;  // Gaussian blur of the projector image, projector px
  // Light of a black projector pixel as a fraction of a full one (finite contrast: 0.001 is
  // 1000:1); [0, 0.2].
  double projectorBlackLevel = 0.0;
  // Display response: emitted = level^gamma per channel, levels in [0, 1]; [1, 3].
  double projectorGamma = 1.0;
};

// The values of CameraResponse::bayer: no mosaic, or the colours of the 2 × 2 cell from its top
// left pixel, row by row.
inline constexpr std::array<std::string_view, 5> kBayerPatterns = {"none", "rggb", "bggr", "grbg",
                                                                   "gbrg"};

struct CameraResponse {
  Mat3 crosstalk = Mat3::Identity();        // camera RGB = crosstalk · scene RGB
  double gain = 1.0;                        // exposure gain
  Vec3 noiseSigma{1.8138, 1.2923, 1.6745};  // Gaussian noise per channel, grey levels
  double defocusSigmaPx = 0.0;              // Gaussian blur of the camera image, camera px
  // grey = 255·(linear/255)^(1/responseGamma), after crosstalk, gain and defocus; [1, 3].
  double responseGamma = 1.0;
  // Relative light loss at the image corner: gain(r) = 1 − vignetting·(r/r_corner)², r from the
  // principal point; [0, 0.8].
  double vignetting = 0.0;
  // Colour-filter mosaic: "none", "rggb", "bggr", "grbg" or "gbrg" (the 2 × 2 cell from the top
  // left). The sensor keeps one channel per pixel after quantisation; a bilinear demosaic
  // restores RGB.
  std::string bayer = "none";
  // Exposure time as a fraction of the frame interval: moving objects are integrated over
  // [frame − exposure/2, frame + exposure/2] (motion blur); [0, 1].
  double exposure = 0.0;
  int exposureSamples = 1;  // time samples over the exposure, 1 to 16; unused when exposure is 0
};

// The most samples per pixel side a scene asks for (64 rays per pixel: beyond that, render larger):
// the limit of scene.json and of config::validateScene(), which the renderer applies.
inline constexpr int kMaxSceneSupersampling = 8;

struct Scene {
  std::vector<Object> objects;
  std::optional<TurntableMount> turntable{};
  Lighting lighting;
  CameraResponse camera;
  int supersampling = 2;  // n × n samples per camera pixel
  // The rig moves as in a hand-held scan (handheld.hpp); none: the rig stands still.
  std::optional<Handheld> handheld;
};

}  // namespace smx::sim
