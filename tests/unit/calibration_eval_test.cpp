// The calibration evaluation's yardsticks (calibration_eval.hpp), checked on rigs whose error is
// known by construction.
#include "calibration_eval.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "smx/algo/lens.hpp"
#include "smx/config/rig_json.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

algo::Rig exampleRig() {
  auto rig = config::loadRig(test::sourceDir() / "boards/sim/rig_2proj_1cam.json");
  EXPECT_TRUE(rig.has_value());
  return *rig;
}

// Moves device d's centre by `shift` (world, metres), keeping its orientation.
void moveCentre(algo::DeviceModel& d, const Eigen::Vector3d& shift) {
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R(d.R.data());
  const auto c = algo::lens::centre(d);
  const Eigen::Vector3d t = -R * (Eigen::Vector3d(c[0], c[1], c[2]) + shift);
  d.t = {t[0], t[1], t[2]};
}

TEST(CalibrationEval, ExactRigHasNoStripeDepthError) {
  const algo::Rig rig = exampleRig();
  DeviceError e;
  measureStripeDepth(rig, rig, 0, e);
  EXPECT_LT(e.depthRmsMm, 1e-3);
  EXPECT_LT(e.depthMaxMm, 1e-3);
}

// proj0 encodes along x (stripes vertical) and sits 0.32 m to the side: moved 1 mm along the
// baseline it shifts every stripe surface, so the depth moves by about z/b · 1 mm.
TEST(CalibrationEval, AProjectorMovedAcrossItsStripesMovesTheDepth) {
  const algo::Rig real = exampleRig();
  algo::Rig moved = real;
  moveCentre(moved.projectors[0], {0.001, 0, 0});
  DeviceError e;
  measureStripeDepth(real, moved, 0, e);
  EXPECT_GT(e.depthRmsMm, 1.0);
  EXPECT_LT(e.depthRmsMm, 6.0);
}

// Along the stripes' direction (cam0's y for proj0) every boundary surface slides into itself:
// no stripe coordinate and no depth changes. The evaluation reports that part of the centre's
// error apart, as undetermined.
TEST(CalibrationEval, AProjectorMovedAlongItsStripesChangesNoDepth) {
  const algo::Rig real = exampleRig();
  algo::Rig moved = real;
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R(real.projectors[0].R.data());
  const Eigen::Vector3d along = R.transpose() * Eigen::Vector3d(0, 1, 0);
  moveCentre(moved.projectors[0], along * 0.005);
  DeviceError e;
  measureStripeDepth(real, moved, 0, e);
  EXPECT_LT(e.depthRmsMm, 1e-3);
}

TEST(CalibrationEval, RealRigsAreDrawnNearTheNominalAndRepeatable) {
  const algo::Rig nominal = exampleRig();
  const algo::Rig a = drawRealRig(nominal, 7);
  const algo::Rig b = drawRealRig(nominal, 7);
  EXPECT_EQ(config::toJson(a), config::toJson(b));
  EXPECT_NE(config::toJson(a), config::toJson(drawRealRig(nominal, 8)));
  EXPECT_TRUE(config::validateRig(a).has_value());
  // The first camera stays the world frame.
  EXPECT_EQ(a.cameras[0].R, nominal.cameras[0].R);
  EXPECT_EQ(a.cameras[0].t, nominal.cameras[0].t);
  for (std::size_t p = 0; p < a.projectors.size(); ++p) {
    const auto ca = algo::lens::centre(a.projectors[p]);
    const auto cn = algo::lens::centre(nominal.projectors[p]);
    const double moved = std::hypot(ca[0] - cn[0], ca[1] - cn[1], ca[2] - cn[2]);
    EXPECT_GT(moved, 0.0019);
    EXPECT_LT(moved, 0.0101);
  }
}

// A projector's fy/fx and its turn about its optical axis change its stripes the same way, so a
// real rig whose aspect strayed would show up as an axis error the stripes cannot see. Lenses keep
// square pixels to about 0.1 %, and so do the drawn rigs.
TEST(CalibrationEval, RealRigsKeepTheNominalAspect) {
  const auto rig = config::loadRig(test::sourceDir() / "boards/sim/rig_3proj_2cam.json");
  ASSERT_TRUE(rig.has_value());
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const algo::Rig real = drawRealRig(*rig, seed);
    const auto check = [](const algo::DeviceModel& n, const algo::DeviceModel& r) {
      EXPECT_NEAR((r.fy() / r.fx()) / (n.fy() / n.fx()), 1.0, 0.0011);
    };
    for (std::size_t c = 0; c < real.cameras.size(); ++c) {
      check(rig->cameras[c], real.cameras[c]);
    }
    for (std::size_t p = 0; p < real.projectors.size(); ++p) {
      check(rig->projectors[p], real.projectors[p]);
    }
  }
}

}  // namespace
}  // namespace smx::host
