// Raw capture end to end on the simulated board (label "sim"): capture-raw over a real TCP
// connection, compared with `stripemux sim --lit` of the same scene, frame and seed; refusals;
// `stripemux capture` and the guided calibration capture against a checkerboard scene.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "calib_capture.hpp"
#include "cli.hpp"
#include "device_client.hpp"
#include "replay_board.hpp"
#include "sim_calibration.hpp"
#include "sim_device.hpp"
#include "smx/config/board_json.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/net/tcp_client.hpp"
#include "smx/protocol/messages.hpp"
#include "smx/protocol/stream_parser.hpp"
#include "smx/sim/png_io.hpp"
#include "smx/sim/sim_board.hpp"
#include "source_dir.hpp"

namespace smx {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kSource = test::sourceDir();
const fs::path kRig1 = kSource / "boards/sim/rig_2proj_1cam.json";

struct CliRun {
  int code;
  std::string out;
  std::string err;
};

CliRun cli(const std::vector<std::string>& args) {
  std::ostringstream out;
  std::ostringstream err;
  const int code = host::runCli(args, {out, err});
  return {code, out.str(), err.str()};
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("smx_capture_sim_test_" + name);
  fs::remove_all(dir);
  return dir;
}

// A checkerboard of 7×5 inner corners (40 mm squares), tilted, in room light before a wall.
// The printed target of the guided-capture tests: 7 × 4 inner corners of 4 cm on a white sheet.
constexpr calib::Target kGuideTarget{.cols = 7, .rows = 4, .squareM = 0.04};

// That target turned 10° about x and 20° about y, 0.75 m ahead, before a light wall.
fs::path checkerScene() {
  const fs::path dir = fs::temp_directory_path() / "smx_capture_sim_test_checker";
  fs::create_directories(dir);
  const host::TargetSheet sheet = host::targetSheet(kGuideTarget);
  const auto view =
      algo::ImageView<const std::uint8_t>::packed(sheet.grey, sheet.width, sheet.height);
  EXPECT_TRUE(sim::writePngGray8(dir / "target.png", *view).has_value());
  const double width = (kGuideTarget.cols + 1 + 2 * host::kTargetMarginSquares) * 0.04;
  const double height = (kGuideTarget.rows + 1 + 2 * host::kTargetMarginSquares) * 0.04;
  const fs::path file = dir / "scene.json";
  std::ofstream(file) << R"({
  "format": "stripemux-scene/1",
  "supersampling": 1,
  "lighting": {"ambient": [0.6, 0.6, 0.6], "projector_power": 0.4},
  "objects": [
    {"name": "board", "shape": {"type": "plane", "width_m": )"
                      << width << R"(, "height_m": )" << height << R"(},
     "pose": {"t": [0.02, 0.0, 0.75], "rotation_deg": [10, 20, 0]},
     "albedo": {"texture": {"path": "target.png", "width_m": )"
                      << width << R"(, "height_m": )" << height << R"(}}},
    {"name": "wall", "shape": {"type": "plane", "width_m": 3, "height_m": 3},
     "pose": {"t": [0, 0, 1.2]}, "albedo": {"rgb": [0.8, 0.8, 0.8]}}
  ]
})";
  return file;
}

// boards/sim rendering `scene` live with the 1-camera rig (seed 1), on a free loopback port.
config::Board renderBoard(const std::string& scene) {
  return test::renderingScene(test::sourceBoard("sim"), scene, config::loadRig(kRig1).value());
}

// Network loop only: a test serves the raw captures itself or calls startCapture().
using RunningDevice = test::SimDevice;

// The device's frame for `mask`, with the capture served here so that the simulated camera's
// frame number (its count of frames delivered) is known.
host::RawCapture captureServedHere(RunningDevice& running, host::DeviceClient& client,
                                   std::uint32_t mask) {
  auto pending =
      std::async(std::launch::async, [&client, mask] { return client.captureRaw(mask, 20s); });
  EXPECT_TRUE(running.serveOne()) << "no capture-raw arrived";
  auto capture = pending.get();
  EXPECT_TRUE(capture.has_value()) << capture.error();
  return capture ? std::move(*capture) : host::RawCapture{};
}

// Given the simulated board rendering the sphere scene (seed 1), when a host captures raw frames
// with no projector and then with proj1 only, then each is the image `stripemux sim --lit` renders
// for that frame number and seed, pixel for pixel.
TEST(CaptureSim, RawFramesAreTheSimulatorsRenderOfTheSameFrameAndLitProjectors) {
  RunningDevice running(renderBoard("sphere"));
  auto client = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_TRUE(client.has_value()) << client.error();

  const fs::path expected = scratch("expected");
  for (const std::string lit : {"none", "proj1"}) {
    const auto run =
        cli({"sim", "--rig", kRig1.string(), "--scene", "sphere", "--seed", "1", "--frames", "2",
             "--lit", lit, "--no-truth", "--out", (expected / lit).string()});
    ASSERT_EQ(run.code, 0) << run.err;
  }
  // The simulated camera renders frame k for its k-th delivered frame.
  ASSERT_EQ(running.control().framesDelivered(0), 0U);
  const host::RawCapture off = captureServedHere(running, *client, 0);
  ASSERT_EQ(running.control().framesDelivered(0), 1U);
  const host::RawCapture lit = captureServedHere(running, *client, 0b10U);
  EXPECT_EQ(running.control().lastExposureMask(0), 0b10U);

  for (const auto& [capture, file] : {std::pair{&off, expected / "none" / "cam0_0.png"},
                                      std::pair{&lit, expected / "proj1" / "cam0_1.png"}}) {
    const auto truth = sim::readPngRgb8(file);
    ASSERT_TRUE(truth.has_value()) << truth.error();
    ASSERT_EQ(capture->images.size(), 1U);
    ASSERT_EQ(capture->width, truth->width);
    ASSERT_EQ(capture->height, truth->height);
    std::size_t differing = 0;
    for (std::size_t i = 0; i < truth->pixels.size(); ++i) {
      differing += capture->images[0][i] == truth->pixels[i] ? 0U : 1U;
    }
    EXPECT_EQ(differing, 0U) << file;
  }
  EXPECT_EQ(off.projectorsMask, 0U);
  EXPECT_EQ(lit.projectorsMask, 0b10U);
  EXPECT_EQ(lit.capture, off.capture + 1);
}

// Given a device replaying frames, when a host's capture-raw is served, then serving it (trigger,
// acquire, encode every band) allocates nothing.
TEST(CaptureSim, ServingARawCaptureAllocatesNothing) {
  config::Board board = test::replayBoard(1, 3);
  RunningDevice running(std::move(board));
  auto client = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_TRUE(client.has_value()) << client.error();
  (void)captureServedHere(running, *client, 0b11U);  // warm up

  auto pending = std::async(std::launch::async, [&] { return client->captureRaw(0b01U, 20s); });
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (!running.device().rawCaptureRequested() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(1ms);
  }
  // The host waits for the bands now, so the counter sees the device alone.
  const test::AllocationCounter allocations;
  const bool served = running.device().serveRawCapture();
  const std::uint64_t heapCalls = allocations.allocations();
  EXPECT_TRUE(served);
  EXPECT_EQ(heapCalls, 0U) << "serving a raw capture allocated";
  const auto capture = pending.get();
  ASSERT_TRUE(capture.has_value()) << capture.error();
  const auto replayed = sim::readPngRgb8(test::replayFrames(1, 3) / "cam0_1.png");
  ASSERT_TRUE(replayed.has_value());
  EXPECT_EQ(capture->images[0], replayed->pixels) << "the second frame replayed";
}

// Bytes of hello, then `requests`, as a host would send them; the device's replies decoded.
std::vector<protocol::Message> exchange(const std::string& address,
                                        const std::vector<std::vector<std::byte>>& requests,
                                        std::size_t replies, protocol::StreamParser& parser) {
  auto socket =
      net::TcpClient::connect(net::parseDeviceAddress(address, 0).value(), 2000ms).value();
  std::array<std::byte, 256> out{};
  EXPECT_TRUE(socket.sendAll(protocol::encode(protocol::Hello{"test"}, out).value(), 1000ms));
  for (const auto& request : requests) {
    EXPECT_TRUE(socket.sendAll(request, 1000ms));
  }
  std::vector<protocol::Message> got;
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (got.size() < replies && std::chrono::steady_clock::now() < deadline) {
    const auto n = socket.receiveSome(parser.writable(), 100ms);
    EXPECT_TRUE(n.has_value());
    parser.commit(n.value_or(0));
    for (auto next = parser.next(); next && next->has_value(); next = parser.next()) {
      got.push_back(**next);
    }
  }
  return got;
}

std::vector<std::byte> bytesOf(const protocol::ProtocolResult<std::span<const std::byte>>& m) {
  return {m->begin(), m->end()};
}

// Given a device, when a host asks for a projector the board lacks or sends a message type the
// firmware does not know, then it is answered with an error saying so (not silence).
TEST(CaptureSim, TheDeviceRefusesWhatItCannotDoWithAnError) {
  RunningDevice running(test::replayBoard(1, 3));
  std::array<std::byte, 64> out{};
  std::vector<std::byte> unknown =
      bytesOf(protocol::encodeEmpty(protocol::MessageType::kStopStream, out));
  unknown[5] = std::byte{42};  // a type from a future protocol, sealed with its CRC
  (void)protocol::sealMessage(unknown, static_cast<protocol::MessageType>(42), 0);
  protocol::StreamParser parser(1 << 20);
  const auto replies =
      exchange(running.address(),
               {bytesOf(protocol::encode(protocol::CaptureRaw{0b100U}, out)), unknown}, 3, parser);
  ASSERT_EQ(replies.size(), 3U);
  EXPECT_EQ(replies[0].type, protocol::MessageType::kCapabilities);
  ASSERT_EQ(replies[1].type, protocol::MessageType::kError);
  ASSERT_EQ(replies[2].type, protocol::MessageType::kError);
  EXPECT_NE(std::string(protocol::decodeError(replies[1].payload)->text).find("projector bit"),
            std::string::npos);
  EXPECT_NE(std::string(protocol::decodeError(replies[2].payload)->text).find("does not know"),
            std::string::npos);
  EXPECT_FALSE(running.device().rawCaptureRequested());
}

// Given a camera that times out during a raw capture, the host is told which camera and why,
// and the next raw capture works.
TEST(CaptureSim, ACameraFailingDuringARawCaptureIsReportedByName) {
  RunningDevice running(test::replayBoard(1, 3));
  auto client = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_TRUE(client.has_value()) << client.error();
  running.control().injectTimeouts(0, 1);
  auto pending = std::async(std::launch::async, [&] { return client->captureRaw(0b10U, 20s); });
  EXPECT_TRUE(running.serveOne()) << "no capture-raw arrived";
  const auto failed = pending.get();
  ASSERT_FALSE(failed.has_value());
  EXPECT_NE(failed.error().find("capture-raw: cam0: no frame from the simulated camera in time "
                                "(timeout)"),
            std::string::npos)
      << failed.error();
  EXPECT_EQ(running.device().counters().captureErrors, 1U);
  EXPECT_EQ(running.hal().trigger.active(), 0U) << "lines left on";
  const auto next = captureServedHere(running, *client, 0b01U);
  EXPECT_EQ(next.images.size(), 1U);
}

// Given a running device, `stripemux capture --sets none,proj0` writes the calibration file names
// at the camera's size; an unknown id is a usage error naming the ids there are.
TEST(CaptureSim, CaptureCommandWritesTheCalibrationNames) {
  RunningDevice running(test::replayBoard(1, 3));
  running.startCapture();
  const fs::path out = scratch("sets");
  const auto run = cli(
      {"capture", "--device", running.address(), "--sets", "none,proj0", "--out", out.string()});
  ASSERT_EQ(run.code, 0) << run.err;
  for (const char* name : {"cam0.png", "proj0.cam0.png"}) {
    const auto image = sim::readPngRgb8(out / name);
    ASSERT_TRUE(image.has_value()) << name << ": " << image.error();
    EXPECT_EQ(image->width, running.board().rig.cameras[0].width);
    EXPECT_EQ(image->height, running.board().rig.cameras[0].height);
  }
  EXPECT_FALSE(fs::exists(out / "proj1.cam0.png"));

  const auto unknown = cli({"capture", "--device", running.address(), "--projectors", "proj0,projX",
                            "--out", scratch("unknown").string()});
  EXPECT_EQ(unknown.code, host::kExitUsage);
  EXPECT_NE(unknown.err.find("no projector \"projX\" (it has proj0, proj1)"), std::string::npos)
      << unknown.err;
}

// Given a device whose capture loop does not run, the host gives up after --timeout and says
// why; nothing is written.
TEST(CaptureSim, ADeviceThatSendsNothingTimesOutClearly) {
  RunningDevice running(test::replayBoard(1, 3));
  const fs::path out = scratch("timeout");
  const auto run = cli({"capture", "--device", running.address(), "--projectors", "all", "--out",
                        out.string(), "--timeout", "0.5"});
  EXPECT_EQ(run.code, host::kExitDeviceOrIo);
  EXPECT_NE(run.err.find("no raw frames from the device within 500 ms"), std::string::npos)
      << run.err;
  EXPECT_FALSE(fs::exists(out / "cam0.png"));
}

host::CaptureGuideOptions guideOptions(int poses) {
  host::CaptureGuideOptions options;
  options.poses = poses;
  options.cols = kGuideTarget.cols;
  options.rows = kGuideTarget.rows;
  options.squareM = kGuideTarget.squareM;
  options.poseTimeout = 20s;
  // A raw capture is a render: under ASan, beside another rendering test, it can pass 10 s.
  options.captureTimeout = 60s;
  return options;
}

// Given a still checkerboard in view, the guided capture writes pose00 in the calibration layout
// with every corner found; a second pose of the same still board is refused as too similar to
// pose00, naming it.
TEST(CaptureSim, GuidedCaptureWritesAPoseAndRefusesOneTooSimilar) {
  RunningDevice running(renderBoard(checkerScene().string()));
  running.startCapture();
  auto client = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_TRUE(client.has_value()) << client.error();
  const fs::path dir = scratch("guided");
  std::ostringstream out;
  std::ostringstream err;
  const auto summary =
      host::captureCalibrationSet(*client, running.board().rig, guideOptions(1), dir, {out, err});
  ASSERT_TRUE(summary.has_value()) << summary.error() << "\n" << out.str();
  ASSERT_EQ(summary->poses.size(), 1U);
  EXPECT_EQ(summary->poses[0].cornersPerCamera, std::vector<int>{28});
  // The board is turned 20° about y and 10° about x: its normal is about 22° off the axis.
  EXPECT_NEAR(summary->poses[0].tiltDeg, 22.3, 2.0);
  for (const char* name : {"cam0.png", "proj0.cam0.png", "proj1.cam0.png"}) {
    EXPECT_TRUE(fs::exists(dir / "pose00" / name)) << name;
  }
  std::ifstream target(dir / "target.json");
  const std::string text((std::istreambuf_iterator<char>(target)), {});
  EXPECT_NE(text.find("\"stripemux-target/1\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"inner_corners\""), std::string::npos) << text;
  EXPECT_NE(out.str().find("28 of 28 corners in cam0"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("image coverage (cam0)"), std::string::npos) << out.str();

  // Again into the same folder: target.json is read back, pose00 exists, and the still board
  // cannot make pose01.
  auto options = guideOptions(2);
  options.cols = 0;  // from target.json
  options.poseTimeout = 3s;
  std::ostringstream again;
  const fs::path second = scratch("guided_twice");
  fs::create_directories(second);
  fs::copy_file(dir / "target.json", second / "target.json");
  const auto refused =
      host::captureCalibrationSet(*client, running.board().rig, options, second, {again, err});
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().find("pose01: "), std::string::npos) << refused.error();
  EXPECT_NE(refused.error().find("too similar to pose00"), std::string::npos) << refused.error();
  EXPECT_TRUE(fs::exists(second / "pose00" / "cam0.png"));
  EXPECT_FALSE(fs::exists(second / "pose01"));
}

// A board that moves between a pose's off frame and its projector frames must not give a pose:
// a board replaying A A A A then B B B B B B (one image per raw capture, the capture loop idle)
// is still at captures 0-1, has moved by capture 4 (the off frame after the projector frames),
// and is accepted at B: captures 5-6 still, 9 the same.
TEST(CaptureSim, GuidedCaptureStartsAPoseOverWhenTheBoardMoved) {
  const fs::path replay = scratch("moved_replay");
  const fs::path shifted = checkerScene().parent_path() / "shifted.json";
  {
    std::ifstream in(checkerScene());
    std::string text((std::istreambuf_iterator<char>(in)), {});
    text.replace(text.find("[0.02, 0.0, 0.75]"), 17, "[0.06, 0.0, 0.75]");
    std::ofstream(shifted) << text;
  }
  for (const auto& [scene, name] : {std::pair{checkerScene(), "a"}, std::pair{shifted, "b"}}) {
    const auto run = cli({"sim", "--rig", kRig1.string(), "--scene", scene.string(), "--lit",
                          "none", "--no-truth", "--out", (replay / name).string()});
    ASSERT_EQ(run.code, 0) << run.err;
  }
  for (int k = 0; k < 10; ++k) {
    fs::copy_file(replay / (k < 4 ? "a" : "b") / "cam0.png",
                  replay / ("cam0_" + std::to_string(k) + ".png"));
  }
  config::Board board = renderBoard("plane");
  board.config.sim.scene.clear();
  board.config.sim.replayDir = replay;
  RunningDevice running(std::move(board), {.loops = test::SimLoops::kServe});
  auto client = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_TRUE(client.has_value()) << client.error();
  const fs::path dir = scratch("moved");
  std::ostringstream out;
  std::ostringstream err;
  const auto summary =
      host::captureCalibrationSet(*client, running.board().rig, guideOptions(1), dir, {out, err});
  ASSERT_TRUE(summary.has_value()) << summary.error() << "\n" << out.str();
  EXPECT_NE(out.str().find("pose00: the board moved while the projector frames were taken"),
            std::string::npos)
      << out.str();
  EXPECT_EQ(running.control().framesDelivered(0), 10U);
  const auto written = sim::readPngRgb8(dir / "pose00" / "cam0.png");
  const auto b = sim::readPngRgb8(replay / "b" / "cam0.png");
  ASSERT_TRUE(written.has_value()) << written.error();
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(written->pixels, b->pixels) << "pose00 is not the board where it held still";
}

// Given a scene without the target, the guided capture gives up on pose00 and says so.
TEST(CaptureSim, GuidedCaptureSaysWhenTheTargetIsNeverFound) {
  RunningDevice running(renderBoard("plane"));
  running.startCapture();
  auto client = host::DeviceClient::connect(running.address(), 3000ms);
  ASSERT_TRUE(client.has_value()) << client.error();
  auto options = guideOptions(1);
  options.poseTimeout = 2s;
  std::ostringstream out;
  std::ostringstream err;
  const auto result = host::captureCalibrationSet(*client, running.board().rig, options,
                                                  scratch("never"), {out, err});
  ASSERT_FALSE(result.has_value());
  EXPECT_NE(result.error().find("pose00: "), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("the target is not found in cam0"), std::string::npos)
      << result.error();
}

}  // namespace
}  // namespace smx
