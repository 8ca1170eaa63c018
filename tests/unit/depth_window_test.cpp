// The owner's depth window (docs/config.md): depths outside [min, max] or below the least
// confidence become "no depth", everything else is left as it was.
#include "smx/algo/depth_window.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/config/rig_json.hpp"
#include "source_dir.hpp"

namespace smx::algo {
namespace {

TEST(DepthWindow, ClearsExactlyThePixelsOutsideTheWindow) {
  // Units of 0.1 mm: the window keeps 500…1500 with confidence ≥ 100.
  std::array<std::uint16_t, 8> depth = {0, 499, 500, 1000, 1500, 1501, 1000, 65535};
  std::array<std::uint8_t, 8> confidence = {0, 200, 200, 99, 100, 200, 255, 255};
  const std::array<std::uint16_t, 8> keptDepth = {0, 0, 500, 0, 1500, 0, 1000, 0};
  const std::array<std::uint8_t, 8> keptConfidence = {0, 0, 200, 0, 100, 0, 255, 0};
  applyDepthWindow(*DepthPlane::packed(depth, 4, 2),
                   *ImageView<std::uint8_t>::packed(confidence, 4, 2),
                   {.minUnits = 500, .maxUnits = 1500, .minConfidence = 100});
  EXPECT_EQ(depth, keptDepth);
  EXPECT_EQ(confidence, keptConfidence);
}

// 0.1 mm units: a window of 0.50005 … 1.25 m keeps the units 5001 … 12500 (both ends inside).
TEST(DepthWindow, PipelineOptionsInMetresBecomeTheUnitsInside) {
  const auto rig = config::loadRig(test::sourceDir() / "boards" / "sim" / "rig_2proj_2cam.json");
  ASSERT_TRUE(rig.has_value()) << rig.error().message();
  PipelineOptions options;
  options.depthUnitM = 1e-4;
  const auto keepAll = prepareCameraPipeline(*rig, 0, options);
  ASSERT_TRUE(keepAll.has_value()) << keepAll.error();
  EXPECT_TRUE(keepAll->window.keepsAll());

  options.minDepthM = 0.50005;
  options.maxDepthM = 1.25;
  options.minConfidence = 40;
  const auto windowed = prepareCameraPipeline(*rig, 0, options);
  ASSERT_TRUE(windowed.has_value()) << windowed.error();
  EXPECT_EQ(windowed->window.minUnits, 5001);
  EXPECT_EQ(windowed->window.maxUnits, 12500);
  EXPECT_EQ(windowed->window.minConfidence, 40);

  options.maxDepthM = 0.4;  // empty
  EXPECT_FALSE(prepareCameraPipeline(*rig, 0, options).has_value());
  options.maxDepthM = 1.25;
  options.minConfidence = 0;
  EXPECT_FALSE(prepareCameraPipeline(*rig, 0, options).has_value());
}

}  // namespace
}  // namespace smx::algo
