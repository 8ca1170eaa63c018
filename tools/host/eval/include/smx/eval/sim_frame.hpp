#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "smx/algo/image_view.hpp"
#include "smx/algo/rig.hpp"
#include "smx/sim/scene.hpp"

// Evaluation (stripemux eval, accuracy tests): one rendered camera frame of a rig and a scene,
// with the simulator's ground truth, in owning buffers.
namespace smx::eval {

template <class T>
struct OwnedPlane {
  int width = 0;
  int height = 0;
  std::vector<T> pixels;

  OwnedPlane() = default;
  OwnedPlane(int w, int h, T fill)
      : width(w),
        height(h),
        pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}
  [[nodiscard]] algo::ImageView<T> view() {
    return *algo::ImageView<T>::packed(pixels, width, height);
  }
  [[nodiscard]] algo::ImageView<const T> view() const {
    return *algo::ImageView<const T>::packed(pixels, width, height);
  }
  [[nodiscard]] const T& at(int x, int y) const {
    return pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                  static_cast<std::size_t>(x)];
  }
};

struct SimFrame {
  algo::Rig rig;
  OwnedPlane<algo::Rgb8> image;
  OwnedPlane<float> depth;
  std::vector<OwnedPlane<std::uint8_t>> lit;  // per projector
  std::vector<OwnedPlane<float>> stripe;      // per projector
};

// The example rig boards/sim/<rigFile> and the named scene <scene> of the data folder
// (sim::dataDir()),
// optionally modified by `edit`; all projectors on. Throws std::runtime_error with the reason.
struct SimRequest {
  std::string rigFile = "rig_2proj_1cam.json";
  std::string scene = "plane";
  int camera = 0;
  int frame = 0;
  std::uint64_t seed = 1;
  int supersampling = 0;  // samples per pixel side; 0: the scene's own
};
[[nodiscard]] SimFrame renderSimFrame(const SimRequest& request);
[[nodiscard]] SimFrame renderSimFrame(const SimRequest& request, const sim::Scene& scene);
[[nodiscard]] SimFrame renderSimFrame(algo::Rig rig, const sim::Scene& scene,
                                      const SimRequest& request = {});
[[nodiscard]] sim::Scene loadNamedScene(const std::string& name);
[[nodiscard]] algo::Rig loadExampleRig(const std::string& file);

}  // namespace smx::eval
