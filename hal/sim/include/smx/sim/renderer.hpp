#pragma once

#include <array>
#include <cstdint>
#include <expected>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/algo/rig.hpp"
#include "smx/sim/scene.hpp"

// The simulated rig's camera: renders what a camera of the rig sees when some projectors are on,
// with exact ground truth (docs/simulator.md). Host-only (Embree, Eigen, double).
namespace smx::sim {

// Ground truth of one projector as seen by one camera, at camera pixel centres.
struct ProjectorTruthViews {
  algo::ImageView<std::uint8_t> litMask;  // 255 where the surface point is lit by the projector
                                          // (inside its image and not shadowed), else 0
  algo::ImageView<float> u;               // continuous projector pixel coordinates, NaN if unlit
  algo::ImageView<float> v;
  algo::ImageView<float> stripe;  // stripe coordinate s (docs/pattern.md), NaN if unlit
};

// Caller-provided ground-truth buffers for one camera; any view may be empty to skip it.
struct GroundTruthViews {
  algo::ImageView<float> depth;                  // z in the camera frame, metres; NaN: none
  algo::ImageView<std::array<float, 3>> normal;  // unit world normal facing the camera
  std::vector<ProjectorTruthViews> projectors;   // one per rig projector, or empty
};

struct FrameRequest {
  int camera = 0;               // index into rig.cameras
  int frame = 0;                // animation frame index
  std::vector<bool> lit;        // per rig projector: on during the exposure
  std::uint64_t seed = 0;       // noise seed; the same (seed, frame, camera) gives the same image
  std::vector<double> power{};  // per rig projector, 0…1 of the scene's power; empty: all full
  double exposureScale = 1.0;   // exposure time over the scene's: scales the light collected
  double gain = 1.0;            // sensor gain: scales the signal and the read noise
  double turntableDeg = 0.0;    // the scene's turntable objects turned by this (scene.hpp)
};

class Renderer {
 public:
  // Builds the acceleration structures for the scene; fails with config::validateScene()'s
  // message on a scene it refuses, and on no other scene (a camera index out of range is checked
  // per frame).
  [[nodiscard]] static std::expected<std::unique_ptr<Renderer>, std::string> create(
      const algo::Rig& rig, const Scene& scene);

  virtual ~Renderer() = default;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders into `image` (the camera's width × height) and, if given, the ground truth.
  [[nodiscard]] virtual std::expected<void, std::string> render(const FrameRequest& request,
                                                                algo::RgbView image,
                                                                GroundTruthViews* truth) = 0;

 protected:
  Renderer() = default;
};

}  // namespace smx::sim
