// scene.json objects' "pose_sequence" (docs/scene-format.md): a target that holds each pose for
// hold_frames frames, then moves to the next, as a person placing a calibration board does.
// Reading, the rules with their messages, and the renderer's frame-to-pose mapping against the
// depth of a plane facing the camera (closed form: the plane's z).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "smx/config/rig_json.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/sim/renderer.hpp"
#include "smx/sim/scene.hpp"
#include "source_dir.hpp"

namespace smx::sim {
namespace {

using config::parseScene;

// One plane object with `sequence` as its pose_sequence value.
std::string sceneWithSequence(std::string_view sequence, std::string_view extra = "") {
  return R"({"format": "stripemux-scene/1", "objects": [{"shape": {"type": "plane"}, )" +
         std::string(extra) + R"("pose_sequence": )" + std::string(sequence) + "}]}";
}

void expectRejected(std::string_view text, std::string_view field, std::string_view part) {
  const auto scene = parseScene(text, ".");
  ASSERT_FALSE(scene.has_value()) << "accepted:\n" << text;
  EXPECT_EQ(scene.error().field, field) << scene.error().message();
  EXPECT_NE(scene.error().problem.find(part), std::string::npos) << scene.error().problem;
}

TEST(PoseSequence, IsReadPoseByPose) {
  const auto scene = parseScene(sceneWithSequence(R"({"hold_frames": 4, "poses": [
      {"t": [0, 0, 0.8]}, {"t": [0.1, 0, 0.9], "R": [0, -1, 0, 1, 0, 0, 0, 0, 1]},
      {"t": [0, 0.2, 1], "rotation_deg": [0, 0, 90], "scale": 2}]})"),
                                ".");
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  const PoseSequence& s = scene->objects[0].poseSequence;
  EXPECT_EQ(s.holdFrames, 4);
  ASSERT_EQ(s.poses.size(), 3U);
  EXPECT_EQ(s.poses[0].t, Vec3(0, 0, 0.8));
  EXPECT_EQ(s.poses[1].t, Vec3(0.1, 0, 0.9));
  EXPECT_EQ(s.poses[1].R(0, 1), -1.0);
  EXPECT_EQ(s.poses[2].R(1, 0), 1.0);  // rotation_deg: 90° about z, exact
  EXPECT_EQ(s.poses[2].scale, 2.0);
  // Left out, hold_frames is 1.
  const auto one = parseScene(sceneWithSequence(R"({"poses": [{"t": [0, 0, 1]}]})"), ".");
  ASSERT_TRUE(one.has_value()) << one.error().message();
  EXPECT_EQ(one->objects[0].poseSequence.holdFrames, 1);
}

TEST(PoseSequence, BadValuesAreRefusedNamingTheKey) {
  expectRejected(sceneWithSequence(R"({"hold_frames": 0, "poses": [{}]})"),
                 "objects[0].pose_sequence.hold_frames", "1");
  expectRejected(sceneWithSequence(R"({"hold_frames": 2.5, "poses": [{}]})"),
                 "objects[0].pose_sequence.hold_frames", "integer");
  expectRejected(sceneWithSequence(R"({"hold_frames": 3})"), "objects[0].pose_sequence.poses",
                 "required field is missing");
  expectRejected(sceneWithSequence(R"({"poses": []})"), "objects[0].pose_sequence.poses",
                 "1 to 1000 poses");
  expectRejected(sceneWithSequence(R"({"poses": {"t": [0, 0, 1]}})"),
                 "objects[0].pose_sequence.poses", "1 to 1000 poses");
  expectRejected(sceneWithSequence(R"({"poses": [{"t": [0, 0, 1]}, {"t": [0, 0]}]})"),
                 "objects[0].pose_sequence.poses[1].t", "3");
  expectRejected(sceneWithSequence(R"({"poses": [{"R": [1, 0, 0, 0, 1, 0, 0, 0, -1]}]})"),
                 "objects[0].pose_sequence.poses[0].R", "reflection");
  expectRejected(sceneWithSequence(R"({"poses": [{"s": 1}]})"), "objects[0].pose_sequence.poses[0]",
                 "\"s\"");
  expectRejected(sceneWithSequence(R"({"hold": 2, "poses": [{}]})"), "objects[0].pose_sequence",
                 "\"hold\"");
  expectRejected(sceneWithSequence(R"([{"t": [0, 0, 1]}])"), "objects[0].pose_sequence",
                 "must be an object");
  expectRejected(sceneWithSequence(R"({"poses": [{}]})", R"("pose": {"t": [0, 0, 1]}, )"),
                 "objects[0].pose_sequence", "no \"pose\" or \"motion\"");
}

TEST(PoseSequence, ValidateSceneAppliesTheSameRules) {
  Scene scene;
  Object o;
  o.poseSequence.poses.resize(2);
  o.poseSequence.holdFrames = 0;
  scene.objects.push_back(o);
  auto valid = config::validateScene(scene);
  ASSERT_FALSE(valid.has_value());
  EXPECT_EQ(valid.error().field, "objects[0].pose_sequence.hold_frames");
  scene.objects[0].poseSequence.holdFrames = 2;
  scene.objects[0].poseSequence.poses[1].scale = 0;
  valid = config::validateScene(scene);
  ASSERT_FALSE(valid.has_value());
  EXPECT_EQ(valid.error().field, "objects[0].pose_sequence.poses[1].scale");
  scene.objects[0].poseSequence.poses[1].scale = 1;
  scene.objects[0].motion.angularDegPerFrame = 1;
  valid = config::validateScene(scene);
  ASSERT_FALSE(valid.has_value());
  EXPECT_EQ(valid.error().field, "objects[0].pose_sequence");
}

// Given a plane facing the camera that holds z = 0.7, 0.9, 1.1 m for 3 frames each, then the depth
// at the image centre is 0.7 for frames 0-2, 0.9 for 3-5, 1.1 for 6-8 and 0.7 again from frame 9.
TEST(PoseSequence, RendererHoldsEachPoseThenSwitches) {
  auto rig = config::loadRig(smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json");
  ASSERT_TRUE(rig.has_value()) << rig.error().message();
  auto& camera = rig->cameras[0];
  // A 9 × 9 window round the principal point keeps the render small.
  camera.K[2] -= 316;
  camera.K[5] -= 236;
  camera.width = 9;
  camera.height = 9;
  Scene scene;
  scene.supersampling = 1;
  scene.camera.noiseSigma = Vec3::Zero();
  Object board;
  board.shape = Plane{1.0, 1.0};
  const std::array<double, 3> depths = {0.7, 0.9, 1.1};
  for (const double z : depths) {
    Pose p;
    p.t = {0.0, 0.0, z};
    board.poseSequence.poses.push_back(p);
  }
  board.poseSequence.holdFrames = 3;
  scene.objects.push_back(board);
  auto renderer = Renderer::create(*rig, scene);
  ASSERT_TRUE(renderer.has_value()) << renderer.error();

  const auto count = static_cast<std::size_t>(camera.width * camera.height);
  std::vector<algo::Rgb8> image(count);
  std::vector<float> depth(count);
  GroundTruthViews truth;
  truth.depth = *algo::ImageView<float>::packed(depth, camera.width, camera.height);
  // Out of order, so that a renderer that only steps forward would fail.
  for (const int frame : {0, 2, 3, 5, 6, 8, 9, 4, 1, 7, 12}) {
    FrameRequest request;
    request.frame = frame;
    request.lit.assign(rig->projectors.size(), false);
    const auto ok = (*renderer)->render(
        request, *algo::RgbView::packed(image, camera.width, camera.height), &truth);
    ASSERT_TRUE(ok.has_value()) << ok.error();
    const double expected = depths[static_cast<std::size_t>((frame / 3) % 3)];
    EXPECT_NEAR(depth[count / 2], expected, 1e-6) << "frame " << frame;
  }
}

}  // namespace
}  // namespace smx::sim
