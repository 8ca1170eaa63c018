#pragma once

#include <array>
#include <cstddef>
#include <expected>
#include <string>
#include <vector>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/rig.hpp"
#include "smx/health/disagreement.hpp"

// The rig's health check (docs/health-check.md): one frame with every projector lit, decoded by
// the camera pipeline; wherever two projectors (on one camera) or two cameras (for one projector)
// measure the same surface, their depths are compared. A calibration that has drifted shows as a
// systematic disagreement, fitted robustly as a plane over the image; each projector gets a
// verdict, naming the one that moved where the rig's geometry allows it. Host code (double,
// allocates).
namespace smx::health {

struct CameraFrame {
  std::size_t camera = 0;  // index into rig.cameras
  algo::ConstRgbView image;
};

struct CheckOptions {
  algo::PipelineOptions pipeline;
  Thresholds thresholds;
};

// What was compared: two projectors on one camera, or one projector seen by two cameras (the
// second camera's depths carried into the first camera's image).
struct Comparison {
  enum class Kind : std::uint8_t { kProjectorPair, kCameraPair };
  Kind kind = Kind::kProjectorPair;
  int camera = 0;       // the image the disagreement is mapped on
  int otherCamera = 0;  // kCameraPair: the camera whose depths are carried over
  int projector = 0;
  int otherProjector = 0;  // kProjectorPair: depth(projector) − depth(otherProjector)
  Disagreement disagreement;
  // Two projectors that only disagree with each other (shapeFitted): the RMS left by fitting
  // each one's small pose change to the disagreement (attribution.hpp), projector's then
  // otherProjector's.
  bool shapeFitted = false;
  std::array<double, 2> shapeResidualMm{};
};

enum class Verdict : std::uint8_t {
  kGood,       // every comparison it takes part in agrees
  kDrifted,    // named as the one that disagrees
  kSuspect,    // in a disagreeing pair that the rig cannot attribute ("proj0 or proj1")
  kNoOverlap,  // not enough overlap with any other projector or camera to judge
};
[[nodiscard]] const char* verdictName(Verdict verdict);

struct ProjectorHealth {
  std::string id;
  Verdict verdict = Verdict::kNoOverlap;
  double disagreementMm =
      0;               // the largest systematic disagreement of its comparisons (RMS of the plane)
  std::string reason;  // one line: why this verdict
};

struct CheckReport {
  std::vector<Comparison> comparisons;
  std::vector<ProjectorHealth> projectors;
  bool healthy = false;  // every projector good
  std::string summary;   // one line
};

// Errors name the camera or projector: a frame for an unknown camera, two frames of one camera,
// an image of the wrong size, a rig the pipeline refuses.
[[nodiscard]] std::expected<CheckReport, std::string> checkRig(
    const algo::Rig& rig, const std::vector<CameraFrame>& frames, const CheckOptions& options = {});

}  // namespace smx::health
