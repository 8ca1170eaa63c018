// The host tool against a hostile device: devices are unauthenticated and discovery can be
// spoofed, so whatever a device sends (ids, names, frames) is input like any file.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "cli.hpp"
#include "cli_harness.hpp"
#include "fake_device.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

std::string exampleRigWith(const std::string& from, const std::string& to) {
  return test::textWith(smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json", from, to);
}

// A device that tells the truth: the example rig, its size, two frames per start. Tests make one
// field of it lie.
test::FakeDeviceScript honestDevice() {
  return {.board = "fake",
          .firmwareVersion = "1.0",
          .rigJson = exampleRigWith("", ""),
          .width = 640,
          .height = 480,
          .framesPerStart = 2};
}

class CliHostileDevice : public test::CliTest {};

// Given a device whose rig names its camera "../../<name>", when `stream` runs, then it refuses
// the device's rig naming the field and writes nothing, inside or outside the output folder
// (not <name>_0.depth.png two folders up, with exit 0).
TEST_F(CliHostileDevice, CameraIdThatIsAPathIsRefusedAndNothingIsWritten) {
  const auto work = dir_ / "a" / "b";
  fs::create_directories(work);
  const std::string escaped = "smx_hostile_device_escaped";
  auto script = honestDevice();
  script.rigJson = exampleRigWith("\"cam0\"", "\"../../" + escaped + "\"");
  test::FakeDevice device(script);
  const auto result = test::runCli({"stream", "--device", device.address(), "--out",
                                    (work / "out").string(), "--frames", "1", "--timeout", "10"});
  EXPECT_EQ(result.code, kExitDeviceOrIo) << result.err;
  EXPECT_NE(result.err.find("cameras[0].id"), std::string::npos) << result.err;
  // out/../../ is dir_/a.
  EXPECT_FALSE(fs::exists(dir_ / "a" / (escaped + "_0.depth.png")));
  EXPECT_FALSE(fs::exists(work / "out"));
}

// Given a device whose firmware version carries terminal escape sequences (a title change, a
// screen clear, a C1 CSI), when `info` and `stream` print it, then no escape byte reaches the
// terminal: each is shown as \xNN.
TEST_F(CliHostileDevice, EscapeSequencesFromTheDeviceNeverReachTheTerminal) {
  for (const std::string command : {"info", "stream"}) {
    auto script = honestDevice();
    script.firmwareVersion =
        "evil\x1b]0;owned\x07\xc2\x9b"
        "2J";
    test::FakeDevice device(script);
    std::vector<std::string> args = {command, "--device", device.address()};
    if (command == "stream") {
      args.insert(args.end(),
                  {"--out", (dir_ / "out").string(), "--frames", "1", "--timeout", "10"});
    }
    const auto result = test::runCli(args);
    EXPECT_EQ(result.code, kExitOk) << command << ": " << result.err;
    const std::string printed = result.out + result.err;
    EXPECT_EQ(printed.find('\x1b'), std::string::npos) << command << ": " << printed;
    EXPECT_EQ(printed.find('\x07'), std::string::npos) << command;
    EXPECT_EQ(printed.find("\xc2\x9b"), std::string::npos) << command;
    EXPECT_NE(printed.find("evil\\x1b]0;owned\\x07\\xc2\\x9b2J"), std::string::npos)
        << command << ": " << printed;
  }
}

// Given a device whose board name is not an id (here an escape sequence), when `info` connects,
// then it refuses the device naming the board name, and the message shows the name escaped.
TEST_F(CliHostileDevice, BoardNameThatIsNotAnIdIsRefused) {
  auto script = honestDevice();
  script.board = "evil\x1b[2J";
  test::FakeDevice device(script);
  const auto result = test::runCli({"info", "--device", device.address()});
  EXPECT_EQ(result.code, kExitDeviceOrIo) << result.err;
  EXPECT_NE(result.err.find("the device's board name"), std::string::npos) << result.err;
  EXPECT_EQ((result.out + result.err).find('\x1b'), std::string::npos) << result.err;
}

// Given a device that announces 4096x4096 images while its rig's camera is 640x480, when `info`
// connects, then it refuses the device: range frames are checked against the announcement, so
// the two must agree.
TEST_F(CliHostileDevice, AnnouncementThatDisagreesWithTheRigIsRefused) {
  auto script = honestDevice();
  script.width = 4096;
  script.height = 4096;
  test::FakeDevice device(script);
  const auto result = test::runCli({"info", "--device", device.address()});
  EXPECT_EQ(result.code, kExitDeviceOrIo) << result.err;
  EXPECT_NE(result.err.find("announced 4096x4096 images, but its rig's cam0 is 640x480"),
            std::string::npos)
      << result.err;
}

}  // namespace
}  // namespace smx::host
