// `stripemux demux`: runs on a rendered frame, writes the debug renderings, and rejects bad
// input naming it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli.hpp"
#include "cli_harness.hpp"
#include "smx/sim/png_io.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

const std::string kRig = (smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json").string();

class CliDemux : public test::CliTest {
 protected:
  // cam0's view of the named plane scene, rendered by `stripemux sim`.
  fs::path renderPlane() {
    const auto out = dir_ / "frame";
    const auto sim = test::runCli(
        {"sim", "--rig", kRig, "--scene", "plane", "--out", out.string(), "--no-truth"});
    EXPECT_EQ(sim.code, kExitOk) << sim.err;
    return out / "cam0.png";
  }
};

// Given a rendered frame, demux reports both projectors' boundaries and writes, per projector,
// a boundary image whose coloured pixels are the boundaries, a separated image and a direction
// image, all at the camera's size.
TEST_F(CliDemux, ReportsEachProjectorAndWritesDebugImages) {
  const auto frame = renderPlane();
  const auto debug = dir_ / "debug";
  const auto result = test::runCli(
      {"demux", "--rig", kRig, "--image", "cam0=" + frame.string(), "--debug", debug.string()});
  ASSERT_EQ(result.code, kExitOk) << result.err;
  for (const std::string projector : {"proj0", "proj1"}) {
    EXPECT_NE(result.out.find(projector + ": "), std::string::npos) << result.out;
    for (const std::string kind : {"boundaries", "separated", "direction"}) {
      const auto image = sim::readPngRgb8(debug / (projector + ".cam0." + kind + ".png"));
      ASSERT_TRUE(image.has_value()) << image.error();
      EXPECT_EQ(image->width, 640);
      EXPECT_EQ(image->height, 480);
    }
    // On the board every row crosses about one boundary per 4.4 px stripe.
    const auto boundaries = sim::readPngRgb8(debug / (projector + ".cam0.boundaries.png"));
    std::size_t coloured = 0;
    for (const auto& px : boundaries->pixels) {
      coloured += (px.r | px.g | px.b) != 0 ? 1U : 0U;
    }
    EXPECT_GT(coloured, 640U * 480U / 6U) << projector;
    EXPECT_LT(coloured, 640U * 480U / 3U) << projector;
  }
}

TEST_F(CliDemux, BadImagesAndCamerasAreRejectedByName) {
  const auto frame = renderPlane();
  const auto unknown = test::runCli({"demux", "--rig", kRig, "--image", "cam7=" + frame.string()});
  EXPECT_EQ(unknown.code, kExitBadInput);
  EXPECT_NE(unknown.err.find("cam7"), std::string::npos) << unknown.err;
  EXPECT_NE(unknown.err.find("cam0"), std::string::npos) << unknown.err;  // the known ones

  const auto noEquals = test::runCli({"demux", "--rig", kRig, "--image", frame.string()});
  EXPECT_EQ(noEquals.code, kExitBadInput);
  EXPECT_NE(noEquals.err.find("CAMERA=FILE"), std::string::npos) << noEquals.err;

  const auto missing =
      test::runCli({"demux", "--rig", kRig, "--image", "cam0=" + (dir_ / "nope.png").string()});
  EXPECT_EQ(missing.code, kExitBadInput);
  EXPECT_NE(missing.err.find("nope.png"), std::string::npos) << missing.err;

  // A frame of another camera size: 320 × 240.
  std::vector<algo::Rgb8> small(320 * 240, algo::Rgb8{10, 20, 30});
  const auto smallFile = dir_ / "small.png";
  ASSERT_TRUE(sim::writePngRgb8(smallFile, *algo::ConstRgbView::packed(small, 320, 240)));
  const auto wrongSize =
      test::runCli({"demux", "--rig", kRig, "--image", "cam0=" + smallFile.string()});
  EXPECT_EQ(wrongSize.code, kExitBadInput);
  EXPECT_NE(wrongSize.err.find("320x240"), std::string::npos) << wrongSize.err;
  EXPECT_NE(wrongSize.err.find("640x480"), std::string::npos) << wrongSize.err;
}

}  // namespace
}  // namespace smx::host
