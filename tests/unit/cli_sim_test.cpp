// `stripemux sim`: the files it writes for a rig and a scene, and how it rejects bad input. The
// renderer's physics is tested in sim_render_test.cpp; here the scenes are chosen so that the
// expected files follow from the scene and rig files alone.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "cli.hpp"
#include "cli_harness.hpp"
#include "smx/sim/pfm_io.hpp"
#include "smx/sim/png_io.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

const fs::path kRig2 = smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json";

class CliSim : public test::CliTest {
 protected:
  // A small, fast scene: a board facing cam0 at 0.9 m, no noise, no supersampling.
  fs::path boardScene(const std::string& extraObject = "") {
    return writeFile("board.json", R"({"format": "stripemux-scene/1", "supersampling": 1,
      "camera_response": {"noise_sigma": [0, 0, 0]},
      "objects": [{"shape": {"type": "plane", "width_m": 2.0, "height_m": 2.0},
                   "pose": {"t": [0, 0, 0.9]}})" +
                                       extraObject + "]}");
  }
};

// Given a board facing the camera at 0.9 m (rig cam0 is the world origin, R = I), when sim runs,
// then the image, the depth (0.9 m everywhere) and every projector's truth files are written.
TEST_F(CliSim, WritesImageAndGroundTruthOfEveryProjector) {
  const auto out = dir_ / "out";
  const auto result = test::runCli(
      {"sim", "--rig", kRig2.string(), "--scene", boardScene().string(), "--out", out.string()});
  ASSERT_EQ(result.code, kExitOk) << result.err;
  EXPECT_NE(result.out.find("cam0.png"), std::string::npos) << result.out;

  const auto image = sim::readPngRgb8(out / "cam0.png");
  ASSERT_TRUE(image.has_value()) << image.error();
  EXPECT_EQ(image->width, 640);
  EXPECT_EQ(image->height, 480);

  const auto depth = sim::readPfm(out / "cam0.depth.pfm");
  ASSERT_TRUE(depth.has_value()) << depth.error();
  ASSERT_EQ(depth->values.size(), 640U * 480U);
  for (const float z : depth->values) {
    ASSERT_NEAR(z, 0.9F, 1e-6F);
  }
  const auto normal = sim::readPfm(out / "cam0.normal.pfm");
  ASSERT_TRUE(normal.has_value()) << normal.error();
  EXPECT_EQ(normal->channels, 3);

  for (const std::string projector : {"proj0", "proj1"}) {
    const auto lit = sim::readPngRgb8(out / (projector + ".cam0.lit.png"));
    ASSERT_TRUE(lit.has_value()) << lit.error();
    std::size_t litCount = 0;
    for (const auto& px : lit->pixels) {
      litCount += px.r == 255 ? 1U : 0U;
    }
    EXPECT_GT(litCount, lit->pixels.size() / 2) << projector;
    for (const std::string plane : {".u.pfm", ".v.pfm", ".stripe.pfm"}) {
      const auto file = sim::readPfm(out / (projector + ".cam0" + plane));
      ASSERT_TRUE(file.has_value()) << file.error();
      // Finite exactly where the projector lights the board.
      for (std::size_t i = 0; i < file->values.size(); ++i) {
        ASSERT_EQ(std::isfinite(file->values[i]), lit->pixels[i].r == 255) << projector << plane;
      }
    }
  }
}

// Given --lit naming one projector, the image shows only its stripes: fewer lit pixels than with
// both on and more than with none.
TEST_F(CliSim, LitSelectsTheProjectorsThatAreOn) {
  const auto scene = boardScene().string();
  const auto brightness = [&](const std::string& lit) {
    const auto out = dir_ / ("lit_" + lit);
    const auto result = test::runCli({"sim", "--rig", kRig2.string(), "--scene", scene, "--out",
                                      out.string(), "--lit", lit, "--no-truth"});
    EXPECT_EQ(result.code, kExitOk) << result.err;
    EXPECT_FALSE(fs::exists(out / "cam0.depth.pfm"));
    const auto image = sim::readPngRgb8(out / "cam0.png");
    double sum = 0.0;
    for (const auto& px : image.value().pixels) {
      sum += px.r + px.g + px.b;
    }
    return sum;
  };
  const double none = brightness("none");
  const double one = brightness("proj0");
  const double both = brightness("all");
  EXPECT_LT(none, one);
  EXPECT_LT(one, both);

  const auto unknown = test::runCli({"sim", "--rig", kRig2.string(), "--scene", scene, "--out",
                                     (dir_ / "x").string(), "--lit", "proj0,proj9"});
  EXPECT_EQ(unknown.code, kExitUsage);
  EXPECT_NE(unknown.err.find("proj9"), std::string::npos) << unknown.err;
}

// Given --frames 2 and a moving box, each frame gets its own file and the box moves between them.
TEST_F(CliSim, SeveralFramesAreNumberedAndAnimated) {
  const auto scene = boardScene(R"(, {"shape": {"type": "box", "size_m": [0.2, 0.2, 0.2]},
      "pose": {"t": [0, 0, 0.7]}, "motion": {"velocity_m_per_frame": [0.15, 0, 0]}})");
  const auto out = dir_ / "out";
  const auto result = test::runCli({"sim", "--rig", kRig2.string(), "--scene", scene.string(),
                                    "--out", out.string(), "--frames", "2"});
  ASSERT_EQ(result.code, kExitOk) << result.err;
  EXPECT_FALSE(fs::exists(out / "cam0.png"));
  const auto d0 = sim::readPfm(out / "cam0_0.depth.pfm");
  const auto d1 = sim::readPfm(out / "cam0_1.depth.pfm");
  ASSERT_TRUE(d0.has_value() && d1.has_value());
  ASSERT_TRUE(sim::readPngRgb8(out / "cam0_1.png").has_value());
  // The box front face (z = 0.6 m) spans x in [-0.1, 0.1] m at frame 0 and [0.05, 0.25] m at
  // frame 1: with f = 800 px its left edge moves from column 186 to column 386.
  const auto at = [](const sim::FloatImage& d, int x, int y) {
    return d.values[static_cast<std::size_t>(y * d.width + x)];
  };
  EXPECT_NEAR(at(*d0, 300, 240), 0.6F, 1e-6F);
  EXPECT_NEAR(at(*d1, 300, 240), 0.9F, 1e-6F);
  EXPECT_NEAR(at(*d1, 450, 240), 0.6F, 1e-6F);
  EXPECT_NEAR(at(*d0, 150, 240), 0.9F, 1e-6F);
}

TEST_F(CliSim, NamedScenesAreFoundAndUnknownNamesListThem) {
  const auto unknown = test::runCli(
      {"sim", "--rig", kRig2.string(), "--scene", "teapot", "--out", (dir_ / "o").string()});
  EXPECT_EQ(unknown.code, kExitBadInput);
  EXPECT_NE(unknown.err.find("teapot"), std::string::npos) << unknown.err;
  EXPECT_NE(unknown.err.find("bunny"), std::string::npos) << unknown.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));

  const auto plane = test::runCli({"sim", "--rig", kRig2.string(), "--scene", "plane", "--out",
                                   (dir_ / "plane").string(), "--no-truth"});
  EXPECT_EQ(plane.code, kExitOk) << plane.err;
  EXPECT_TRUE(fs::exists(dir_ / "plane/cam0.png"));
}

// A bad scene names the file and the field (or the missing mesh's path) and writes nothing.
TEST_F(CliSim, BadSceneIsRejectedWithFileAndFieldAndNothingWritten) {
  const auto out = dir_ / "out";
  const auto badField = writeFile("bad.json", R"({"format": "stripemux-scene/1",
    "objects": [{"shape": {"type": "sphere", "radius_m": -1}}]})");
  const auto field = test::runCli(
      {"sim", "--rig", kRig2.string(), "--scene", badField.string(), "--out", out.string()});
  EXPECT_EQ(field.code, kExitBadInput);
  EXPECT_NE(field.err.find("bad.json"), std::string::npos) << field.err;
  EXPECT_NE(field.err.find("objects[0].shape.radius_m"), std::string::npos) << field.err;

  const auto noMesh = writeFile("nomesh.json", R"({"format": "stripemux-scene/1",
    "objects": [{"shape": {"type": "mesh", "path": "missing/teapot.ply"}}]})");
  const auto mesh = test::runCli(
      {"sim", "--rig", kRig2.string(), "--scene", noMesh.string(), "--out", out.string()});
  EXPECT_EQ(mesh.code, kExitBadInput);
  EXPECT_NE(mesh.err.find("missing/teapot.ply"), std::string::npos) << mesh.err;

  const auto truncated = writeFile("truncated.json", R"({"format": "stripemux-scene/1", "obj)");
  const auto json = test::runCli(
      {"sim", "--rig", kRig2.string(), "--scene", truncated.string(), "--out", out.string()});
  EXPECT_EQ(json.code, kExitBadInput);
  EXPECT_NE(json.err.find("truncated.json"), std::string::npos) << json.err;

  EXPECT_FALSE(fs::exists(out));
}

TEST_F(CliSim, UsageErrorsExitOne) {
  EXPECT_EQ(test::runCli({"sim", "--scene", "plane", "--out", "x"}).code, kExitUsage);
  EXPECT_EQ(test::runCli(
                {"sim", "--rig", kRig2.string(), "--scene", "plane", "--out", "x", "--frames", "0"})
                .code,
            kExitUsage);
}

}  // namespace
}  // namespace smx::host
