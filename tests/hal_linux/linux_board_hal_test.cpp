#include <gtest/gtest.h>

#include "smx/hal/board_hal.hpp"

namespace smx::hal {
namespace {

// A two-camera, two-projector rig and the board that matches it.
struct Fixture {
  Fixture() {
    rig.cameras.resize(2);
    rig.cameras[0].id = "left";
    rig.cameras[1].id = "right";
    rig.projectors.resize(2);
    rig.projectors[0].id = "proj0";
    rig.projectors[1].id = "proj1";
    board.name = "test-board";
    board.backend = "linux";
    for (const char* id : {"left", "right"}) {
      board.cameras.push_back(CameraConfig{.id = id,
                                           .device = "/dev/smx-no-such-video",
                                           .format = {640, 480, PixelFormat::kYuyv, 30},
                                           .buffers = 4,
                                           .controls = {}});
    }
    board.trigger.lines = {{.role = "proj0", .chip = "gpiochip0", .offset = 1},
                           {.role = "proj1", .chip = "gpiochip0", .offset = 2}};
    board.network.port = 0;
  }
  algo::Rig rig;
  BoardConfig board;
};

std::string errorOf(const Fixture& f) {
  auto hal = createBoardHal(f.board, f.rig);
  return hal ? std::string("(created)") : hal.error();
}

TEST(LinuxBoardHal, IsTheLinuxBackend) {
  EXPECT_EQ(halBackend(), "linux");
}

TEST(LinuxBoardHal, ABoardThatDoesNotMatchTheRigIsRefusedWithTheField) {
  Fixture f;
  f.board.cameras[1].id = "centre";
  EXPECT_EQ(errorOf(f),
            "board 'test-board': cameras[1].id: 'centre', the rig's camera 1 is 'right'");

  Fixture g;
  g.board.cameras.pop_back();
  EXPECT_EQ(errorOf(g), "board 'test-board': cameras: the board has 1 cameras, the rig 2");

  Fixture h;
  h.board.trigger.lines[0].role = "proj1";
  EXPECT_EQ(errorOf(h),
            "board 'test-board': trigger.lines[0].role: 'proj1', the rig's projector 0 is 'proj0'");
}

TEST(LinuxBoardHal, AMissingCameraIsNamedWithItsFieldAndDevice) {
  const Fixture f;
  const std::string error = errorOf(f);
  EXPECT_EQ(error.rfind("cameras[0]: cannot open /dev/smx-no-such-video", 0), 0U) << error;
}

TEST(LinuxBoardHal, NonV4l2CameraDevicesAreNotSupportedByThisBuild) {
  Fixture f;
  f.board.cameras[0].device = "libcamera:imx219";
  const std::string error = errorOf(f);
  EXPECT_EQ(error.rfind("cameras[0].device: 'libcamera:imx219'", 0), 0U) << error;
}

}  // namespace
}  // namespace smx::hal
