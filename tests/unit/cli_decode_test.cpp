// `stripemux decode`: the documented outputs on a rendered frame, checked against the
// simulator's ground truth, and bad input rejected by name.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli.hpp"
#include "cli_harness.hpp"
#include "png_claim.hpp"
#include "smx/sim/mesh_io.hpp"
#include "smx/sim/pfm_io.hpp"
#include "smx/sim/ply_io.hpp"
#include "smx/sim/png_io.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

const std::string kRig2Cam = (smx::test::sourceDir() / "boards/sim/rig_2proj_2cam.json").string();

class CliDecode : public test::CliTest {
 protected:
  fs::path frames() {
    const auto out = dir_ / "frame";
    const auto sim =
        test::runCli({"sim", "--rig", kRig2Cam, "--scene", "plane", "--out", out.string()});
    EXPECT_EQ(sim.code, kExitOk) << sim.err;
    return out;
  }
};

// A PNG's size, bit depth and colour type, read from its IHDR chunk (bytes 16–25 of the file).
struct PngKind {
  int width = 0;
  int height = 0;
  int bitDepth = 0;
  int colourType = -1;  // 0 grey
};

PngKind pngKind(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::array<unsigned char, 26> head{};
  file.read(reinterpret_cast<char*>(head.data()), head.size());
  const auto be32 = [&](std::size_t at) {
    return static_cast<int>(head[at] << 24U | head[at + 1] << 16U | head[at + 2] << 8U |
                            head[at + 3]);
  };
  return {be32(16), be32(20), head[24], head[25]};
}

// Share of the truth's surface pixels with depth, and of those the share within 3 mm.
struct Agreement {
  double completeness = 0;
  double within3mm = 0;
};

Agreement compareWithTruth(const sim::Gray16Image& depth, const sim::FloatImage& truth,
                           double unitM) {
  int surface = 0;
  int valid = 0;
  int close = 0;
  for (int i = 0; i < depth.width * depth.height; ++i) {
    const float z = truth.values[static_cast<std::size_t>(i)];
    const std::uint16_t d = depth.pixels[static_cast<std::size_t>(i)];
    if (!std::isfinite(z)) {
      continue;
    }
    ++surface;
    if (d != 0) {
      ++valid;
      close += std::abs(d * unitM - z) <= 0.003 ? 1 : 0;
    }
  }
  return {static_cast<double>(valid) / surface, static_cast<double>(close) / std::max(valid, 1)};
}

// Given two cameras' renders of the board, decode writes per camera and per pair 16-bit depth
// PNGs in 0.1 mm units that agree with the rendered truth, coloured PLY clouds whose points
// are at the board, and meta.json with the depth unit and per-stage timings.
TEST_F(CliDecode, WritesDepthPointCloudsAndMetaThatMatchTheTruth) {
  const auto in = frames();
  const auto out = dir_ / "out";
  const auto debug = dir_ / "debug";
  const auto result = test::runCli(
      {"decode", "--rig", kRig2Cam, "--image", "cam0=" + (in / "cam0.png").string(), "--image",
       "cam1=" + (in / "cam1.png").string(), "--out", out.string(), "--debug", debug.string()});
  ASSERT_EQ(result.code, kExitOk) << result.err;

  std::ifstream metaFile(out / "meta.json");
  const auto meta = nlohmann::json::parse(metaFile);
  EXPECT_DOUBLE_EQ(meta.at("depth_unit_m").get<double>(), 0.0001);
  ASSERT_EQ(meta.at("cameras").size(), 2U);
  for (const std::string stage : {"demux", "decode", "triangulate", "merge", "total"}) {
    EXPECT_GT(meta["cameras"][0]["timings_ms"].at(stage).get<double>(), 0.0) << stage;
  }

  std::size_t points = 0;
  for (const std::string cam : {"cam0", "cam1"}) {
    const auto truth = sim::readPfm(in / (cam + ".depth.pfm"));
    ASSERT_TRUE(truth) << truth.error();
    for (const std::string& name : {cam, "proj0." + cam, "proj1." + cam}) {
      const auto depth = sim::readPngGray16(out / (name + ".depth.png"));
      ASSERT_TRUE(depth) << depth.error();
      ASSERT_EQ(depth->width, 640);
      const Agreement a = compareWithTruth(*depth, *truth, 0.0001);
      EXPECT_GT(a.completeness, 0.8) << name;
      EXPECT_GT(a.within3mm, 0.97) << name;
    }
    // The confidence plane beside the merged depth: 8-bit grey of the camera's size, 0 exactly
    // where the depth is 0 (docs/cli.md).
    const fs::path confidencePath = out / (cam + ".confidence.png");
    const PngKind kind = pngKind(confidencePath);
    EXPECT_EQ(kind.width, 640) << cam;
    EXPECT_EQ(kind.height, 480) << cam;
    EXPECT_EQ(kind.bitDepth, 8) << cam;
    EXPECT_EQ(kind.colourType, 0) << cam;
    const auto confidence = sim::readPngRgb8(confidencePath);
    const auto depth = sim::readPngGray16(out / (cam + ".depth.png"));
    ASSERT_TRUE(confidence && depth);
    ASSERT_EQ(confidence->pixels.size(), depth->pixels.size());
    int mismatched = 0;
    for (std::size_t i = 0; i < depth->pixels.size(); ++i) {
      mismatched += (confidence->pixels[i].r == 0) != (depth->pixels[i] == 0) ? 1 : 0;
    }
    EXPECT_EQ(mismatched, 0) << cam << ": confidence 0 where depth is not, or the reverse";
    EXPECT_EQ(meta["cameras"][cam == "cam0" ? 0 : 1].at("confidence").get<std::string>(),
              cam + ".confidence.png");

    const auto cloud = sim::readPlyPoints(out / (cam + ".ply"));
    ASSERT_TRUE(cloud) << cloud.error();
    EXPECT_GT(cloud->size(), 640U * 480U * 6U / 10U) << cam;
    points += cloud->size();
    ASSERT_TRUE(fs::exists(debug / ("proj0." + cam + ".stripes.png")));
    ASSERT_TRUE(fs::exists(debug / (cam + ".depth.png")));
  }
  const auto merged = sim::readPlyPoints(out / "merged.ply");
  ASSERT_TRUE(merged) << merged.error();
  EXPECT_EQ(merged->size(), points);
  EXPECT_EQ(meta.at("merged_points").get<std::size_t>(), points);
  // Both cameras see the same board: its points from either camera lie on one plane in the
  // world (the scene's board faces the rig at 0.9 m); check all points share one depth band.
  double zMin = 1e9;
  double zMax = -1e9;
  for (const auto& p : *merged) {
    zMin = std::min(zMin, static_cast<double>(p.z));
    zMax = std::max(zMax, static_cast<double>(p.z));
  }
  EXPECT_LT(zMax - zMin, 0.3);
}

TEST_F(CliDecode, BadImagesAndCamerasExitTwoNamingThem) {
  const auto in = frames();
  const auto out = (dir_ / "out").string();
  const auto unknown = test::runCli(
      {"decode", "--rig", kRig2Cam, "--image", "cam7=" + (in / "cam0.png").string(), "--out", out});
  EXPECT_EQ(unknown.code, kExitBadInput);
  EXPECT_NE(unknown.err.find("cam7"), std::string::npos) << unknown.err;

  const auto missing = test::runCli({"decode", "--rig", kRig2Cam, "--image",
                                     "cam0=" + (dir_ / "nope.png").string(), "--out", out});
  EXPECT_EQ(missing.code, kExitBadInput);
  EXPECT_NE(missing.err.find("nope.png"), std::string::npos) << missing.err;

  std::vector<algo::Rgb8> small(320 * 240, algo::Rgb8{10, 20, 30});
  const auto smallFile = dir_ / "small.png";
  ASSERT_TRUE(sim::writePngRgb8(smallFile, *algo::ConstRgbView::packed(small, 320, 240)));
  const auto wrongSize = test::runCli(
      {"decode", "--rig", kRig2Cam, "--image", "cam1=" + smallFile.string(), "--out", out});
  EXPECT_EQ(wrongSize.code, kExitBadInput);
  EXPECT_NE(wrongSize.err.find("320x240"), std::string::npos) << wrongSize.err;
  EXPECT_NE(wrongSize.err.find("small.png"), std::string::npos) << wrongSize.err;

  const auto usage = test::runCli({"decode", "--rig", kRig2Cam, "--out", out});
  EXPECT_EQ(usage.code, kExitUsage);
}

// Given a 65-byte PNG claiming 20000x20000 pixels for a 640x480 camera, when decoded, then the
// command exits 2 naming the file and both sizes, having refused the header before allocating
// the 1.2 GB it claims.
TEST_F(CliDecode, ImageClaimingAHugeSizeExitsTwoNamingTheFileAndBothSizes) {
  const auto bomb = test::pngClaiming(20000, 20000);
  const auto file = dir_ / "bomb.png";
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char*>(bomb.data()), static_cast<std::streamsize>(bomb.size()));
  const auto result = test::runCli({"decode", "--rig", kRig2Cam, "--image", "cam0=" + file.string(),
                                    "--out", (dir_ / "out").string()});
  EXPECT_EQ(result.code, kExitBadInput);
  EXPECT_NE(result.err.find("bomb.png: image is 20000x20000, camera cam0 is 640x480"),
            std::string::npos)
      << result.err;
}

}  // namespace
}  // namespace smx::host
