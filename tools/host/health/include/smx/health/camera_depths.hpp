#pragma once

#include <expected>
#include <string>
#include <vector>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/range_image.hpp"
#include "smx/algo/rig.hpp"

// One camera image through the camera pipeline, kept per projector: each projector's range image
// (before merging, docs/decode.md) and its decoded stripe coordinates. Host code.
namespace smx::health {

struct CameraDepths {
  int camera = 0;
  int width = 0;
  int height = 0;
  double depthUnitM = algo::kDefaultDepthUnitM;
  std::vector<std::vector<std::uint16_t>> depth;     // per projector, depth units, 0 = none
  std::vector<std::vector<algo::StripeQ16>> stripe;  // per projector

  [[nodiscard]] std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(x);
  }
};

// Errors name the camera: an image of the wrong size, a rig the pipeline refuses.
[[nodiscard]] std::expected<CameraDepths, std::string> decodeCameraDepths(
    const algo::Rig& rig, int camera, algo::ConstRgbView image,
    const algo::PipelineOptions& options);

}  // namespace smx::health
