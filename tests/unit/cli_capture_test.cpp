// `stripemux capture` against devices that cannot or will not capture raw frames, and the host's
// reading of raw-frame bands, which come from an unauthenticated device.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "calib_capture.hpp"
#include "cli.hpp"
#include "cli_harness.hpp"
#include "device_client.hpp"
#include "fake_device.hpp"
#include "raw_frames.hpp"
#include "smx/protocol/messages.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

class CliCapture : public test::CliTest {};

// Given a device whose firmware predates capture-raw (it skips the request, as the fake device
// does), when `capture` runs, then it gives up after --timeout naming the firmware and the
// likely cause, with exit 3 and no files.
TEST_F(CliCapture, AFirmwareWithoutRawCaptureIsNamedAfterTheTimeout) {
  test::FakeDevice device(
      {.board = "fake",
       .firmwareVersion = "0.9",
       .rigJson = test::textWith(smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json", "", ""),
       .width = 640,
       .height = 480});
  const auto result = test::runCli({"capture", "--device", device.address(), "--out",
                                    (dir_ / "out").string(), "--timeout", "0.3"});
  EXPECT_EQ(result.code, kExitDeviceOrIo) << result.err;
  EXPECT_NE(result.err.find("firmware 0.9 may predate raw capture"), std::string::npos)
      << result.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "cam0.png"));
}

TEST_F(CliCapture, GuidedTargetMustBeColsByRows) {
  for (const std::string bad : {"9", "9x", "x6", "9x6x2", "nine x6"}) {
    const auto result = test::runCli({"capture", "--device", "127.0.0.1:1", "--guided", "--out",
                                      (dir_ / "out").string(), "--target", bad});
    // Refused before connecting (nothing listens on port 1).
    EXPECT_EQ(result.code, kExitUsage) << bad;
    EXPECT_NE(result.err.find("--target: expected COLSxROWS"), std::string::npos) << result.err;
  }
  const auto both = test::runCli({"capture", "--device", "127.0.0.1:1", "--projectors", "none",
                                  "--sets", "none", "--out", (dir_ / "out").string()});
  EXPECT_EQ(both.code, kExitUsage) << both.err;
}

// Given a capture folder whose target.json lies in one field, the guided capture refuses it
// naming the file and the key, before it asks the device for anything.
TEST_F(CliCapture, AHostileTargetFileIsRefusedNamingTheKey) {
  test::FakeDevice device(
      {.board = "fake",
       .firmwareVersion = "1.0",
       .rigJson = test::textWith(smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json", "", ""),
       .width = 640,
       .height = 480});
  auto client = DeviceClient::connect(device.address(), std::chrono::milliseconds(3000));
  ASSERT_TRUE(client.has_value()) << client.error();
  const std::string good =
      R"({"format": "stripemux-target/1", "type": "checkerboard", "inner_corners": [9, 6], )"
      R"("square_m": 0.025})";
  for (const auto& [from, to, key] :
       {std::tuple<std::string, std::string, std::string>{"[9, 6]", "[1, 6]", "inner_corners[0]:"},
        {"[9, 6]", "[9.5, 6]", "inner_corners[0]:"},
        {"[9, 6]", "[9, 6, 2]", "inner_corners:"},
        {"[9, 6]", "[9, 100000]", "inner_corners[1]:"},
        {"0.025", "-0.025", "square_m:"},
        {"0.025", "\"1\"", "square_m:"},
        {"/1", "/2", "format:"},
        {"checkerboard", "charuco", "type:"},
        {"\"type\"", "\"typo\"", "unknown key \"typo\""},
        {"{", "[", "not valid JSON"}}) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    const fs::path dir = dir_ / "captures";
    fs::create_directories(dir);
    std::ofstream(dir / "target.json") << text;
    std::ostringstream out;
    std::ostringstream err;
    const auto result =
        captureCalibrationSet(*client, client->info().rig, CaptureGuideOptions{}, dir, {out, err});
    ASSERT_FALSE(result.has_value()) << text;
    EXPECT_NE(result.error().find("target.json: " + key), std::string::npos) << text << "\n"
                                                                             << result.error();
  }
}

std::vector<std::byte> band(const protocol::RawFrameHeader& header, int width, int height) {
  std::vector<algo::Rgb8> pixels(static_cast<std::size_t>(width * height), algo::Rgb8{1, 2, 3});
  std::vector<std::byte> buffer(protocol::rawFrameBound(width, height));
  const auto message =
      protocol::encodeRawFrame(header, *algo::ConstRgbView::packed(pixels, width, height), buffer);
  EXPECT_TRUE(message.has_value());
  return {message->begin() + protocol::kHeaderBytes, message->end()};
}

// Given a capture of 2 cameras of 4×3 asked with projector mask 1, bands that tile both frames
// complete it; each lie of a band is refused naming what it claimed against what was announced.
TEST(RawFrameAssembler, BandsAreCheckedAgainstTheAnnouncementAndTheRequest) {
  const AnnouncedFrames announced{.cameras = 2, .width = 4, .height = 3};
  auto good = RawFrameAssembler::create(announced, 1);
  ASSERT_TRUE(good.has_value());
  for (std::uint8_t camera = 0; camera < 2; ++camera) {
    ASSERT_TRUE(good->add(band(
        {.camera = camera, .projectorsMask = 1, .firstRow = 0, .rows = 2, .capture = 7}, 4, 3)));
    EXPECT_FALSE(good->complete());
    ASSERT_TRUE(good->add(band(
        {.camera = camera, .projectorsMask = 1, .firstRow = 2, .rows = 1, .capture = 7}, 4, 3)));
  }
  ASSERT_TRUE(good->complete());
  const RawCapture capture = good->take();
  EXPECT_EQ(capture.capture, 7U);
  ASSERT_EQ(capture.images.size(), 2U);
  EXPECT_EQ(capture.images[1][11], (algo::Rgb8{1, 2, 3}));

  const auto refused = [&](const std::vector<std::byte>& payload, const std::string& needle,
                           bool afterFirstBand = false) {
    auto assembler = RawFrameAssembler::create(announced, 1);
    ASSERT_TRUE(assembler.has_value());
    if (afterFirstBand) {
      ASSERT_TRUE(assembler->add(band({.projectorsMask = 1, .rows = 1, .capture = 7}, 4, 3)));
    }
    const auto added = assembler->add(payload);
    ASSERT_FALSE(added.has_value()) << needle;
    EXPECT_NE(added.error().find(needle), std::string::npos) << added.error();
  };
  refused(band({.camera = 2, .projectorsMask = 1, .rows = 1}, 4, 3), "announced 2 cameras");
  refused(band({.projectorsMask = 1, .rows = 1}, 5, 3), "raw frame of 5x3, but");
  refused(band({.projectorsMask = 1, .rows = 1}, 4, 300), "raw frame of 4x300, but");
  refused(band({.projectorsMask = 3, .rows = 1}, 4, 3), "but 1 was asked for");
  refused(band({.projectorsMask = 1, .rows = 1, .capture = 7}, 4, 3),
          "row 0 of camera 0 sent twice", true);
  refused(band({.projectorsMask = 1, .firstRow = 1, .rows = 1, .capture = 8}, 4, 3),
          "bands of two captures", true);
  refused(std::vector<std::byte>(10), "shorter than its header");
}

// A device that announces more pixels than a raw capture may hold is refused before anything is
// allocated (8192 × 8192 × 2 cameras is 384 MiB of RGB).
TEST(RawFrameAssembler, AnOversizedAnnouncementIsRefusedBeforeAllocating) {
  const auto big = RawFrameAssembler::create({.cameras = 2, .width = 8192, .height = 8192}, 0);
  ASSERT_FALSE(big.has_value());
  EXPECT_NE(big.error().find("more than the"), std::string::npos) << big.error();
  EXPECT_FALSE(RawFrameAssembler::create({.cameras = 0, .width = 4, .height = 4}, 0).has_value());
}

}  // namespace
}  // namespace smx::host
