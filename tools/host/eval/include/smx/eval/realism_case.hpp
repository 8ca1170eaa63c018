#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/sim/scene.hpp"

// The randomised realism suite's scenes and rigs (`stripemux eval --only realism`,
// docs/results.md): one case per (seed, index), drawn from the product's envelope. Host code,
// double precision; deterministic for (seed, index, options) on every platform (its own random
// numbers, no <random> distributions). Throws std::runtime_error when a mesh cannot be loaded.
//
// Rig (world frame = cam0's, metres; rig.hpp conventions):
//   - 1–2 cameras (cam1 8–20 cm beside cam0), 2–3 projectors, every device aimed at the target
//     point T on cam0's axis at the working distance D ∈ [0.5, 1.2] m;
//   - encoding axes: each projector's stripe gradient, as cam0 sees it on the fronto-parallel
//     plane through T at the image centre, points along a drawn image direction φ_p; two
//     projectors differ by 60–90°, three are 60° apart (the only spacing of three lines with every
//     pair ≥ 60°). A projector sits along φ_p from the cameras (±15°), so its axis runs near its
//     epipolar direction, as the example rigs do;
//   - camera–projector baselines 8–25 cm for every pair, projectors set back 0–10 cm;
//   - stripes 3–8 px wide in cam0 on that plane at T (pattern stripePx from the local
//     camera → projector Jacobian), and wide enough that the 198 stripes span the projector image;
//   - cameras 640 × 480 (× cameraScale), f for a 45–65° horizontal view, principal point within
//     ±2 % of the centre, k1 k2 p1 p2 k3 distortion; projectors 1024 × 768 or 1280 × 800, throw
//     ratio 1.1–2.0, vertical lens shift (principal point 10–40 % of the height below the centre,
//     the projector tilted so that T stays at the image centre), distortion when
//     projectorDistortion is set, mounted level within ±4° of roll.
// Scene: 1–3 objects (bunny, head, sphere, box, cylinder, plane) around T with random poses and
//   scales, a background wall (tilted up to 25°) and/or an oblique floor under the objects;
//   albedo grey, coloured, saturated, dark or checker-textured; optics from the ranges of
//   docs/simulator.md (the paper's noise, ambient, projector power with 1/d², defocus of projector
//   and camera, colour crosstalk, gain, projector black level 0.1–2 % and gamma 1.8–2.4, camera
//   response gamma 1–2.2, vignetting up to 40 %, a Bayer mosaic, motion blur over an exposure of
//   up to half a frame, gloss up to 0.3).
namespace smx::eval {

struct RealismOptions {
  bool projectorDistortion = true;
  double cameraScale = 1.0;  // camera size and focal length relative to 640 × 480
};

struct RealismCase {
  int index = 0;
  algo::Rig rig;
  sim::Scene scene;
  double workingDistanceM = 0;        // D: T = (0, 0, D) in cam0's frame
  std::vector<double> axisDeg;        // φ_p per projector, cam0 image, degrees
  std::vector<double> stripeWidthPx;  // designed width in cam0 on the plane at T, per projector
  std::string summary;                // one line: devices, distance, objects, background
};

[[nodiscard]] RealismCase generateRealismCase(std::uint64_t seed, int index,
                                              const RealismOptions& options = {});

}  // namespace smx::eval
