// scan::Tracker (docs/tracking.md) on the head_handheld scene's true depth:
// the tracked trajectory against the simulator's true rig poses (sim::handheldRigPose, relative
// to frame 0), frames behind the hand reported lost and not fused, tracking resumed after them
// without a jump, and a jump in the trajectory recovered through the keyframes.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <numbers>
#include <vector>

#include "smx/config/rig_json.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/eval/frame_eval.hpp"
#include "smx/eval/sim_frame.hpp"
#include "smx/scan/tracker.hpp"
#include "smx/sim/handheld.hpp"
#include "smx/sim/renderer.hpp"
#include "source_dir.hpp"

namespace smx::scan {
namespace {

constexpr double kDepthUnitM = 1e-4;
// A 1-second occlusion (15 frames at 15 fps) after 20 frames of tracking.
constexpr int kOccludedFrom = 20;
constexpr int kOccludedFrames = 15;
constexpr int kFrames = 55;

// The head_handheld scene's frames as true depth (the renderer's ground truth, quantised as a
// device sends it), rendered once for the suite.
class HeadHandheld : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto rig = config::loadRig(smx::test::sourceDir() / "boards/sim-handheld/rig.json");
    ASSERT_TRUE(rig.has_value()) << rig.error().message();
    auto scene = config::loadScene(smx::test::sourceDir() / "hal/sim/scenes/head_handheld.json");
    ASSERT_TRUE(scene.has_value()) << scene.error().message();
    ASSERT_TRUE(scene->handheld.has_value());
    // Truth only: no image worth shading finely or adding noise to.
    scene->supersampling = 1;
    scene->camera.exposure = 0;
    scene->camera.noiseSigma = sim::Vec3::Zero();
    scene->handheld->occlusion = {
        .fromFrame = kOccludedFrom, .frames = kOccludedFrames, .distanceM = 0.08};
    rig_ = *rig;
    handheld_ = *scene->handheld;
    auto renderer = sim::Renderer::create(rig_, *scene);
    ASSERT_TRUE(renderer.has_value()) << renderer.error();
    renderer_ = std::move(*renderer);
  }
  static void TearDownTestSuite() {
    renderer_.reset();
    views_.clear();
  }

  // Frame f's true depth, rendered on first use (each test renders only the frames it needs).
  static const RangeView& view(int f) {
    if (const auto it = views_.find(f); it != views_.end()) {
      return it->second;
    }
    const auto& camera = rig_.cameras[0];
    const auto count = static_cast<std::size_t>(camera.width * camera.height);
    std::vector<algo::Rgb8> image(count);
    std::vector<float> depth(count);
    sim::GroundTruthViews truth;
    truth.depth = *algo::ImageView<float>::packed(depth, camera.width, camera.height);
    sim::FrameRequest request;
    request.frame = f;
    request.lit.assign(rig_.projectors.size(), false);
    const auto ok = renderer_->render(
        request, *algo::RgbView::packed(image, camera.width, camera.height), &truth);
    EXPECT_TRUE(ok.has_value()) << ok.error();
    RangeView v;
    v.id = std::to_string(f);
    v.depthUnitM = kDepthUnitM;
    CameraRange range{camera.width, camera.height, std::vector<std::uint16_t>(count, 0), {}};
    for (std::size_t i = 0; i < count; ++i) {
      if (std::isfinite(depth[i])) {
        range.depth[i] = static_cast<std::uint16_t>(std::lround(depth[i] / kDepthUnitM));
      }
    }
    v.cameras.push_back(std::move(range));
    return views_.emplace(f, std::move(v)).first->second;
  }

  // Rig → rig at frame 0: the model frame of a tracker started on frame 0.
  static Pose truth(int frame) {
    return sim::handheldRigPose(handheld_, 0.0).inverse() * sim::handheldRigPose(handheld_, frame);
  }

  static inline algo::Rig rig_;
  static inline sim::Handheld handheld_;
  static inline std::unique_ptr<sim::Renderer> renderer_;
  static inline std::map<int, RangeView> views_;
};

struct Errors {
  double translationMm = 0.0;
  double rotationDeg = 0.0;
};

Errors poseError(const Pose& got, const Pose& expected) {
  const Pose d = expected.inverse() * got;
  return {d.translation().norm() * 1e3,
          Eigen::AngleAxisd(d.linear()).angle() * 180.0 / std::numbers::pi};
}

// Given 55 frames of a hand-held loop with a hand over the lenses for frames 20–34, then every
// other frame tracks to within 1 mm and 0.2° RMS of the true pose, the covered frames are lost
// and not fused, and the first frame after them registers again without a jump.
TEST_F(HeadHandheld, TracksThroughAnOcclusion) {
  auto tracker = Tracker::create(rig_);
  ASSERT_TRUE(tracker.has_value()) << tracker.error();
  double sumT = 0.0;
  double sumR = 0.0;
  int tracked = 0;
  double worstT = 0.0;
  for (int f = 0; f < kFrames; ++f) {
    const TrackResult r = tracker->track(view(f));
    const bool occluded = f >= kOccludedFrom && f < kOccludedFrom + kOccludedFrames;
    if (occluded) {
      EXPECT_EQ(r.state, TrackingState::kLost) << "frame " << f;
      EXPECT_FALSE(r.fused) << "frame " << f;
      continue;
    }
    ASSERT_NE(r.state, TrackingState::kLost) << "frame " << f << ": " << r.reason;
    if (f == kOccludedFrom + kOccludedFrames) {
      EXPECT_EQ(r.state, TrackingState::kRelocalised);
    }
    EXPECT_TRUE(r.fused) << "frame " << f << " fitness " << r.quality.fitness << " rmse "
                         << r.quality.inlierRmseMm;
    const Errors e = poseError(r.pose, truth(f));
    // No jump: the resumed pose is as close to the truth as any tracked one.
    EXPECT_LT(e.translationMm, 2.0) << "frame " << f;
    EXPECT_LT(e.rotationDeg, 0.4) << "frame " << f;
    sumT += e.translationMm * e.translationMm;
    sumR += e.rotationDeg * e.rotationDeg;
    worstT = std::max(worstT, e.translationMm);
    ++tracked;
  }
  const double rmsT = std::sqrt(sumT / tracked);
  const double rmsR = std::sqrt(sumR / tracked);
  std::printf("tracked %d frames: RMS %.3f mm %.4f deg, worst %.3f mm; %zu keyframes\n", tracked,
              rmsT, rmsR, worstT, tracker->keyframes());
  EXPECT_LE(rmsT, 1.0);
  EXPECT_LE(rmsR, 0.2);
}

// Given frames 0–24, then frame 44 (24° further round: as if the hand moved fast behind a
// cover), then the tracker finds it through a keyframe and its pose is right.
TEST_F(HeadHandheld, RelocalisesAfterAJumpThroughTheKeyframes) {
  auto tracker = Tracker::create(rig_);
  ASSERT_TRUE(tracker.has_value()) << tracker.error();
  for (int f = 0; f < 20; ++f) {
    ASSERT_NE(tracker->track(view(f)).state, TrackingState::kLost) << "frame " << f;
  }
  ASSERT_GE(tracker->keyframes(), 2U);
  TrackResult r;
  for (const int f : {44, 45}) {
    r = tracker->track(view(f));
    if (r.state != TrackingState::kLost) {
      const Errors e = poseError(r.pose, truth(f));
      EXPECT_LT(e.translationMm, 2.0) << "frame " << f;
      EXPECT_LT(e.rotationDeg, 0.4) << "frame " << f;
    }
  }
  EXPECT_NE(r.state, TrackingState::kLost) << r.reason;
}

// Given 6 frames of the head_handheld scene as the device would see and decode them (both
// projectors on, the scene's motion blur and camera noise, the firmware's camera pipeline),
// then every frame tracks and the trajectory is within 1 mm and 0.2° RMS of the true one.
TEST(HeadHandheldDecoded, TracksDecodedFrames) {
  const algo::Rig rig = eval::loadExampleRig("rig_2proj_1cam.json");
  const sim::Scene scene = eval::loadNamedScene("head_handheld");
  ASSERT_TRUE(scene.handheld.has_value());
  const auto start = sim::handheldRigPose(*scene.handheld, 0.0);
  auto tracker = Tracker::create(rig);
  ASSERT_TRUE(tracker.has_value()) << tracker.error();
  double sumT = 0.0;
  double sumR = 0.0;
  constexpr int kDecoded = 6;
  for (int f = 0; f < kDecoded; ++f) {
    const eval::SimFrame frame = eval::renderSimFrame(rig, scene, {.frame = f, .seed = 7});
    const auto run = eval::runPipeline(frame, 0);
    const algo::ConstDepthPlane depth = run->pipeline->merged();
    RangeView v;
    v.depthUnitM = kDepthUnitM;
    CameraRange range{depth.width(), depth.height(), {}, {}};
    for (int y = 0; y < depth.height(); ++y) {
      for (int x = 0; x < depth.width(); ++x) {
        range.depth.push_back(depth(x, y));
      }
    }
    v.cameras.push_back(std::move(range));
    const TrackResult r = tracker->track(v);
    ASSERT_NE(r.state, TrackingState::kLost) << "frame " << f << ": " << r.reason;
    const Errors e = poseError(r.pose, start.inverse() * sim::handheldRigPose(*scene.handheld, f));
    std::printf(
        "decoded frame %d: %zu points, fitness %.3f, rmse %.3f mm, fused %d; error %.3f mm "
        "%.4f deg\n",
        f, r.points, r.quality.fitness, r.quality.inlierRmseMm, r.fused ? 1 : 0, e.translationMm,
        e.rotationDeg);
    sumT += e.translationMm * e.translationMm;
    sumR += e.rotationDeg * e.rotationDeg;
  }
  EXPECT_LE(std::sqrt(sumT / kDecoded), 1.0);
  EXPECT_LE(std::sqrt(sumR / kDecoded), 0.2);
}

TEST(Tracker, RefusesBadOptions) {
  algo::Rig rig;
  EXPECT_FALSE(Tracker::create(rig).has_value());
  auto loaded = config::loadRig(smx::test::sourceDir() / "boards/sim-handheld/rig.json");
  ASSERT_TRUE(loaded.has_value());
  TrackerOptions o;
  o.minDepthM = 2.0;
  EXPECT_FALSE(Tracker::create(*loaded, o).has_value());
  o = {};
  o.weakFitness = 0.9;
  EXPECT_FALSE(Tracker::create(*loaded, o).has_value());
}

}  // namespace
}  // namespace smx::scan
