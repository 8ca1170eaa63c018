#pragma once

#include <cstdint>
#include <expected>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/calib/target.hpp"
#include "smx/sim/scene.hpp"

// Simulated calibration captures (`stripemux sim --calibration N`, docs/simulator.md): a printed
// checkerboard in N seeded, hand-placed-looking poses, rendered by every camera with the projectors
// off and with each projector on alone, in the capture layout of docs/cli.md, with the truth the
// calibration is measured against.
namespace smx::host {

// The printed target `stripemux sim --calibration` shows unless told otherwise: 11 × 8 inner
// corners of 30 mm squares, an A3 sheet, large enough at the rigs' working distance to fill a
// good part of the image.
inline constexpr calib::Target kDefaultCalibrationTarget{.cols = 11, .rows = 8, .squareM = 0.03};

inline constexpr std::string_view kCalibrationTruthFormat = "stripemux-calibration-truth/1";

// The printed sheet's white margin round the squares, in squares: findChessboardCorners needs a
// light border round the outer squares.
inline constexpr int kTargetMarginSquares = 1;
// Paper albedo as 8-bit texels (printed black is not black): 204/255 = 0.8 and 13/255 ≈ 0.05.
inline constexpr std::uint8_t kPaperWhite = 204;
inline constexpr std::uint8_t kPrintedBlack = 13;
// Frames each pose is held in DIR/truth/scene.json, about a second at the device's frame rate.
inline constexpr int kSceneHoldFrames = 30;

// The depth along the first camera's axis where that axis point lies deepest inside every
// projector's image: where the rig's projectors and camera are aimed.
[[nodiscard]] double workingDistanceM(const algo::Rig& rig);

// target.json text for `target`.
[[nodiscard]] std::string targetJson(const calib::Target& target);

// Target → world (cam0 frame in the example rigs): X = R·x + t.
struct TargetPose {
  sim::Mat3 R = sim::Mat3::Identity();
  sim::Vec3 t = sim::Vec3::Zero();
};

// The world points of the inner corners, row by row (index = row · cols + col).
[[nodiscard]] std::vector<sim::Vec3> targetCorners(const calib::Target& target,
                                                   const TargetPose& pose);

// `count` poses drawn from `seed`: the board at the rig's working distance, filling 20–70 % of
// the first camera's image, tilted up to 45° about varied axes and turned in its plane up to
// ±30°, facing every camera and projector; every sixth pose (index 5, 11, …) partly out of some
// camera's view, the others wholly in every camera's view. Every corner a camera sees lies inside
// every projector's image. Fails when the rig leaves no such pose.
[[nodiscard]] std::expected<std::vector<TargetPose>, std::string> drawTargetPoses(
    const algo::Rig& rig, const calib::Target& target, int count, std::uint64_t seed);

// The scene of the captures: the target as a textured plane that holds poses[k] for
// `holdFrames` frames each, room light in [0.35, 0.6] drawn from `seed`, and with `realism` the
// realistic optics drawn from their documented ranges (docs/simulator.md). The texture's texels
// are filled; its path is "target.png".
[[nodiscard]] sim::Scene calibrationScene(const calib::Target& target,
                                          const std::vector<TargetPose>& poses, int holdFrames,
                                          std::uint64_t seed, bool realism);

// The printed sheet, one pixel per square (the texture of calibrationScene()).
struct TargetSheet {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> grey;  // row-major
};
[[nodiscard]] TargetSheet targetSheet(const calib::Target& target);

// scene.json text of calibrationScene()'s scene (readable by config::loadScene() beside
// target.png).
[[nodiscard]] std::string calibrationSceneJson(const sim::Scene& scene);
// DIR/truth/poses.json text.
[[nodiscard]] std::string targetPosesJson(const std::vector<TargetPose>& poses);
// "pose00", "pose01", …
[[nodiscard]] std::string poseDirName(int index);

}  // namespace smx::host
